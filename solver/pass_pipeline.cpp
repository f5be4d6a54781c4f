#include "solver/pass_pipeline.hpp"

#include "solver/graph_solver.hpp"

#include <algorithm>

namespace cairn {

void PassPipeline::plan(const GraphProblem& p, int dynamic_end) {
  planned_ = true;
  items_.clear();
  for (size_t c = 0; c < p.colours.size(); ++c) {
    const GraphColour& gc = p.colours[c];
    const std::int32_t n = gc.group_end - gc.group_begin + gc.batch_end - gc.batch_begin;
    for (std::int32_t i = 0; i < n; ++i) items_.push_back({static_cast<std::int32_t>(c), i});
  }
  // Two walks: the last item to touch each body, then per item the latest
  // of those over its bodies, and itself (its own constraints' impulses).
  last_.assign(static_cast<size_t>(std::max(dynamic_end, 1)), -1);
  need_.resize(items_.size());
  for (int walk = 0; walk < 2; ++walk)
    for (size_t k = 0; k < items_.size(); ++k) {
      bodies_.clear();
      appendItemBodies(p, items_[k], dynamic_end, bodies_);
      std::int32_t need = static_cast<std::int32_t>(k) + 1;
      for (const std::int32_t b : bodies_) {
        if (walk == 0) last_[static_cast<size_t>(b)] = static_cast<std::int32_t>(k);
        else need = std::max(need, last_[static_cast<size_t>(b)] + 1);
      }
      if (walk == 1) need_[k] = need;
    }
}

}  // namespace cairn
