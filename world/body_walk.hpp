// A walk over every body slot, on the pool's threads when there are enough
// bodies: the guards' and watchers' per-body work after each stage. Each
// call writes only its own body's entries; whatever needs the bodies in
// order (an event, a sum) is done after, on the calling thread, so no
// result depends on the split.
#pragma once

#include "world/parallel_thresholds.hpp"
#include "world/world_impl.hpp"

#include <atomic>

namespace cairn::detail {

// Whether a walk over every body slot is worth the pool's threads: the
// bodies that were awake at the last islands stage (an asleep body is a
// test and a skip in most walks, and an asleep pile-1000's walks, split,
// were slower than on one thread). Only the split depends on it, never a
// result.
inline bool splitBodyWalk(const WorldImpl& w) {
  return w.pool_ && static_cast<int>(w.bodies_.size()) - w.ctx_.asleep_bodies >= kParallelBodies;
}

// Calls fn(i) for every body slot i; true when some call returned true.
template <class F>
bool anyBody(WorldImpl& w, F&& fn) {
  const int count = static_cast<int>(w.bodies_.size());
  const auto range = [&](int begin, int end) {
    bool any = false;
    for (int i = begin; i < end; ++i) any = fn(static_cast<size_t>(i)) || any;
    return any;
  };
  if (!splitBodyWalk(w)) return range(0, count);
  std::atomic<bool> found{false};
  w.pool_->parallelFor(count, [&](int begin, int end) {
    if (range(begin, end)) found.store(true, std::memory_order_relaxed);
  });
  return found.load(std::memory_order_relaxed);
}

// The guards' and watchers' pattern: test(i) for every body slot (split as
// above; the test only reads), then, only if some body passed,
// handle(i) for each that passes test(i) again, in body order on the
// calling thread (a handle may change what a later test reads: a frozen
// island's other bodies no longer pass).
template <class Test, class Handle>
void handleFound(WorldImpl& w, Test&& test, Handle&& handle) {
  if (!anyBody(w, test)) return;
  for (size_t i = 0; i < w.bodies_.size(); ++i)
    if (test(i)) handle(i);
}

}  // namespace cairn::detail
