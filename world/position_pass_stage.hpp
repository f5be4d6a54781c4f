// Stage 7b: the nonlinear joint position pass for the islands solved
// directly or exactly (world/joint_position_pass.cpp).
#pragma once

#include "world/world_impl.hpp"

namespace cairn::detail {

// Before the rows are built: each joint's anchor separation as the
// substep begins (the pass leaves joints pulled apart to the capped rows).
void recordJointErrors(WorldImpl& w, StepContext& ctx);
// Projects the rigid bilateral joint rows of every live non-PGS island
// onto C(x) = 0 by Newton steps, moving positions only.
void correctJointPositions(WorldImpl& w, StepContext& ctx);

}  // namespace cairn::detail
