// Consecutive passes over one island's colours run side by side, each a
// few constraints behind the one before it.
//
// A sweep is several passes over the same constraints in the same order:
// the normal rows, then the friction rows, then (NNCG) the momentum step
// that starts the next sweep's normal rows. Only the end of a sweep needs
// all of its constraints done (the per-island stopping test and NNCG's
// beta sum over the whole sweep). Between those points, pass j + 1's
// constraint i needs of pass j only the constraints that last touched its
// own dynamic bodies, which in a pyramid's level order come a level ahead
// of i. So pass j + 1 can run on another
// thread, trailing pass j by about that much: a wavefront (software
// pipeline) over Gauss-Seidel passes, instead of splitting each pass's
// colours, which a small island's colours of one to three batches cannot
// feed (colour_flow.hpp). Every body still sees its constraints in the one
// thread's order, so the bits are one thread's. No wait can deadlock: pass
// j waits only for pass j - 1, which waits for nothing later.
//
// Pass j runs on thread j % threads; a thread runs its passes in order.
// What it costs: the trailing pass reads the bodies and impulses the
// leading one has just written on another core, so it pays only where a
// pass trails by a small share of its items (graph_solver.cpp,
// kPipelineBatches; docs/performance.md).
//
// On one thread the same plan interleaves the passes: after each item of
// the leading pass, every later pass runs as far as its needs allow. The
// order differs from pass after pass only between constraints that share
// no body, so the bits are the same; what changes is the memory traffic.
// A pass after pass sweep streams every batch from beyond the core's
// cache once per pass when the island's batches outgrow it (a
// 5,050-box pyramid's are 24 MB); interleaved, the trailing passes find a
// batch and its bodies where the leading pass left them, a level back.
#pragma once

#include "solver/colour_flow.hpp"
#include "solver/worker_pool.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace cairn {

struct GraphProblem;

class PassPipeline {
 public:
  PassPipeline() : progress_(std::make_unique<Progress[]>(kMaxOverlappedPasses)) {}
  // A copy has the plan but counters of its own.
  PassPipeline(const PassPipeline& o) : PassPipeline() { *this = o; }
  PassPipeline& operator=(const PassPipeline& o) {
    planned_ = o.planned_;
    items_ = o.items_;
    need_ = o.need_;
    return *this;
  }

  // Lists the items of `p`'s colours in order (each colour's row groups,
  // then its batches) and, per item, how many items of the pass before it
  // must be done first: up to the last one that touches one of its dynamic
  // bodies, solver bodies [1, dynamic_end).
  void plan(const GraphProblem& p, int dynamic_end);
  bool planned() const { return planned_; }
  void reset() { planned_ = false; }

  // Runs fn(j, item) for passes j = 0 .. passes - 1 over every item on the
  // calling thread, interleaved: after each item of the first pass not yet
  // done, every later pass runs as far as its needs allow.
  template <class F>
  void runInterleaved(int passes, F&& fn) {
    // The lead's passes before are done, so it is always ready.
    const auto ready = [&](int j, const std::int32_t* pos, bool) {
      return j == 0 || need_[static_cast<size_t>(pos[j])] <= pos[j - 1];
    };
    interleavePasses(passes, static_cast<std::int32_t>(items_.size()), ready,
                     [&](int j, std::int32_t i) { fn(j, items_[static_cast<size_t>(i)]); });
  }

  // Runs fn(j, item) for passes j = 0 .. passes - 1 over every item, on
  // min(passes, pool threads) threads.
  template <class F>
  void run(WorkerPool& pool, int passes, F&& fn) {
    for (int j = 0; j < passes; ++j) progress_[j].done.store(0, std::memory_order_relaxed);
    const int threads = std::min(passes, pool.threads());
    pool.parallelFor(threads, [&](int t, int) {
      for (int j = t; j < passes; j += threads) runPass(j, fn);
    });
  }

 private:
  struct alignas(64) Progress {
    std::atomic<std::int32_t> done{0};  // items of this pass finished
  };

  template <class F>
  void runPass(int j, F& fn) {
    const std::int32_t n = static_cast<std::int32_t>(items_.size());
    std::int32_t seen = j == 0 ? n : 0;  // what this thread last saw of pass j - 1
    for (std::int32_t i = 0; i < n; ++i) {
      const std::int32_t need = need_[static_cast<size_t>(i)];
      if (need > seen) seen = WorkerPool::waitAtLeast(progress_[j - 1].done, need);
      fn(j, items_[static_cast<size_t>(i)]);
      progress_[j].done.store(i + 1, std::memory_order_release);
    }
  }

  bool planned_ = false;
  std::vector<FlowItem> items_;
  std::vector<std::int32_t> need_;  // per item: items of the pass before to wait for
  // Planning scratch: per body, the last item to touch it; every item's
  // bodies, item k's at [body_begin_[k], body_begin_[k + 1]).
  std::vector<std::int32_t> last_, bodies_, body_begin_;
  std::unique_ptr<Progress[]> progress_;
};

}  // namespace cairn
