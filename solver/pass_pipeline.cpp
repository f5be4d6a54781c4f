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
  // The last item to touch each body, then per item the latest of those
  // over its bodies, and itself (its own constraints' impulses).
  last_.assign(static_cast<size_t>(std::max(dynamic_end, 1)), -1);
  body_begin_.assign(1, 0);
  bodies_.clear();
  for (size_t k = 0; k < items_.size(); ++k) {
    appendItemBodies(p, items_[k], dynamic_end, bodies_);
    for (std::int32_t q = body_begin_.back(); q < static_cast<std::int32_t>(bodies_.size()); ++q)
      last_[static_cast<size_t>(bodies_[static_cast<size_t>(q)])] = static_cast<std::int32_t>(k);
    body_begin_.push_back(static_cast<std::int32_t>(bodies_.size()));
  }
  need_.resize(items_.size());
  for (size_t k = 0; k < items_.size(); ++k)  // the flow's plan of the pass before, on one thread
    passBeforeNeed({bodies_.data() + body_begin_[k], static_cast<size_t>(body_begin_[k + 1] - body_begin_[k])},
                   last_.data(), 1, 0, static_cast<std::int32_t>(k), &need_[k]);
}

}  // namespace cairn
