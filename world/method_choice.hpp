// Each island's solver under solver.method = "auto", and the counts the
// step statistics report (world/method_choice.cpp).
#pragma once

#include "world/world_impl.hpp"

namespace cairn::detail {

// After the islands are built: sets ctx.island_method and ctx.island_reason
// (every island the setting's method, reason Setting, unless it is Auto).
void chooseIslandMethods(WorldImpl& w, StepContext& ctx);
// StepStats::islands_by_method and islands_by_reason from the choice.
void countIslandMethods(WorldImpl& w, const StepContext& ctx);

}  // namespace cairn::detail
