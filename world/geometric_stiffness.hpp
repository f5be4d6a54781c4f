// Stage 5a/6a: the joints' geometric stiffness folded into the rotational
// inertia the rows of direct and exact islands see (world/geometric_stiffness.cpp).
#pragma once

#include "world/world_impl.hpp"

namespace cairn::detail {

// Before the rows are built: inertia I + h^2 K from last substep's joint forces.
void stiffenRotations(WorldImpl& w, StepContext& ctx);
// After the solve: the bodies' true inertia back.
void restoreRotations(WorldImpl& w, StepContext& ctx);

}  // namespace cairn::detail
