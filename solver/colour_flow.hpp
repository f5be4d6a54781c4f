// The colours of one large island swept by several threads with no barrier
// between colours.
//
// A colour's constraints share no dynamic body, so threads can split each
// colour and meet at a barrier after it (graph_solver.cpp, forColour). A
// stack's level order makes many small colours instead: a pyramid's
// colours hold one to a few batches each, and a barrier per colour costs
// about what the second thread saves. Here each thread takes, in every
// colour, one contiguous run of the colour's items, and before an item it
// waits only for the items of other threads that last touched one of its
// dynamic bodies: a dataflow schedule over the same order, in the manner
// of the dependency graphs Jolt builds between its jobs (JobSystem.h),
// here fixed per step and per body. Every body still sees its constraints
// in colour order, one at a time, so a pass gives the same bits as one
// thread's. No wait can deadlock: an item waits only for items of earlier
// colours.
//
// The threads walk their runs toward each other: the first thread from
// the start of its run, the last from the end. A colour's items come in
// the order their constraints were made, which for a stack built row by
// row is the order of its bodies, left to right; then the items at the
// border between two threads' runs come last in both, and the next
// colour's border items, the ones that wait for the other thread, find
// their predecessors done a colour earlier. In any other order the
// schedule is as correct, only slower.
//
// The plan is made once per (sub)step for the graph built in it, and used
// by every pass over the colours (warm start, sweeps, momentum, correction)
// whose items touch the bodies the plan saw.
#pragma once

#include "solver/worker_pool.hpp"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace cairn {

struct GraphProblem;

// The most passes one overlapped run takes (pass_pipeline.hpp): the warm
// start or momentum, then the normal rows and the friction rows.
inline constexpr int kMaxOverlappedPasses = 3;

// Runs `passes` consecutive passes of `n` items each, interleaved, on the
// calling thread: one item of the first unfinished pass (the lead), then
// each later pass's items as far as they are ready; again until every pass
// is done. ready(j, pos, wait) says whether pass j's next item, pos[j], may
// run (pos[k] is pass k's count of items done); with `wait` it may wait for
// other threads first, and it is asked so only for the lead, whose passes
// before are all done. run(j, i) runs pass j's item i. The one-thread
// pipeline (pass_pipeline.hpp) and each of the flow's threads (below) run
// their passes through it.
template <class Ready, class Run>
void interleavePasses(int passes, std::int32_t n, Ready&& ready, Run&& run) {
  std::int32_t pos[kMaxOverlappedPasses] = {};
  for (int lead = 0; lead < passes;) {
    if (pos[lead] == n) {
      ++lead;
      continue;
    }
    ready(lead, pos, true);
    run(lead, pos[lead]++);
    for (int j = lead + 1; j < passes; ++j)
      while (pos[j] < n && ready(j, pos, false)) run(j, pos[j]++);
  }
}

// The items of the pass before that an item waits for when passes are
// interleaved, per thread u: up to u's last item over the whole pass to
// touch one of the item's bodies, and on its own thread (`thread`, where
// it is item `at`) itself, whose impulses it reads. last_at[b T + u] is
// the place in u's order of u's last item to touch body b (-1: none).
// Writes out[0 .. T). One thread's pipeline (pass_pipeline.cpp) and the
// flow's threads (colour_flow.cpp) plan with it.
inline void passBeforeNeed(std::span<const std::int32_t> bodies, const std::int32_t* last_at, std::size_t T,
                           std::size_t thread, std::int32_t at, std::int32_t* out) {
  for (std::size_t u = 0; u < T; ++u) out[u] = 0;
  out[thread] = at + 1;
  for (const std::int32_t b : bodies)
    for (std::size_t u = 0; u < T; ++u) out[u] = std::max(out[u], last_at[static_cast<std::size_t>(b) * T + u] + 1);
}

// Item `item` of colour `colour`: its row groups, then its batches
// (graph_solver.cpp's item numbering).
struct FlowItem {
  std::int32_t colour = 0, item = 0;
};

// Appends to `out` the dynamic bodies (solver bodies [1, dynamic_end)) that
// item `it` writes: its row group's rows' bodies, or its batch's lanes' in
// use.
void appendItemBodies(const GraphProblem& p, FlowItem it, int dynamic_end, std::vector<std::int32_t>& out);

class ColourFlow {
 public:
  ColourFlow() = default;
  // A copy has the plan but counters of its own.
  ColourFlow(const ColourFlow& o) { *this = o; }
  ColourFlow& operator=(const ColourFlow& o);

  // Plans the colours of `p` (one part, in order) for `threads` threads;
  // solver bodies [1, dynamic_end) are the ones written. Returns whether
  // the schedule pays: its critical path, in batch visits, at least
  // `min_saving` visits shorter than one thread's pass. Else nothing is
  // planned and the caller splits colour by colour.
  bool plan(const GraphProblem& p, int threads, int dynamic_end, double min_saving);
  // Whether plan() has run since the last reset(), and whether it made a
  // schedule to run.
  bool planned() const { return planned_; }
  bool ready() const { return threads_ > 0; }
  void reset() {
    threads_ = 0;
    planned_ = false;
  }

  // Runs fn(item) for every item on `pool` (whose thread count the plan
  // was made for): each thread its own items, each after the other
  // threads' items it waits for.
  template <class F>
  void run(WorkerPool& pool, F&& fn) {
    for (int t = 0; t < threads_; ++t) progress_[t].done.store(0, std::memory_order_relaxed);
    pool.parallelFor(threads_, [&](int t, int) { runThread(t, fn); });
  }

  // Runs fn(j, item) for consecutive passes j = 0 .. passes - 1 over every
  // item, each thread its own items in every pass, interleaved as on one
  // thread (pass_pipeline.hpp): after each item of its first unfinished
  // pass, a thread runs its later passes' items as far as they are ready.
  // An item of pass j is ready when the items of pass j it waits for in
  // run() are done, and those of pass j - 1 that touch its bodies, on any
  // thread. Only the first unfinished pass waits; no wait can deadlock: the
  // earliest unfinished item of the lowest unfinished pass waits for
  // nothing.
  template <class F>
  void runInterleaved(WorkerPool& pool, int passes, F&& fn) {
    for (int k = 0; k < passes * threads_; ++k) progress_[k].done.store(0, std::memory_order_relaxed);
    pool.parallelFor(threads_, [&](int t, int) { runThreadInterleaved(t, passes, fn); });
  }

 private:
  struct alignas(64) Progress {
    std::atomic<std::int32_t> done{0};  // items of this thread finished in this pass
  };

  // Whether thread u has done `count` of its items in pass j; waits for it
  // if `wait`.
  bool reached(int j, int u, std::int32_t count, bool wait) const {
    const std::atomic<std::int32_t>& done = progress_[j * threads_ + u].done;
    if (wait) return WorkerPool::waitAtLeast(done, count) >= count;
    return done.load(std::memory_order_acquire) >= count;
  }

  template <class F>
  void runThreadInterleaved(int t, int passes, F& fn) {
    const std::int32_t first = thread_begin_[static_cast<size_t>(t)];
    const std::int32_t n = thread_begin_[static_cast<size_t>(t) + 1] - first;
    const auto ready = [&](int j, const std::int32_t* pos, bool wait) {
      const size_t k = static_cast<size_t>(first + pos[j]) * static_cast<size_t>(threads_);
      for (int u = 0; u < threads_; ++u) {
        const std::int32_t same = need_[k + static_cast<size_t>(u)];
        const std::int32_t before = j > 0 ? prev_need_[k + static_cast<size_t>(u)] : 0;
        if (u == t) {
          if (j > 0 && before > pos[j - 1]) return false;  // this thread's own pass before
          continue;
        }
        if (same > 0 && !reached(j, u, same, wait)) return false;
        if (before > 0 && !reached(j - 1, u, before, wait)) return false;
      }
      return true;
    };
    interleavePasses(passes, n, ready, [&](int j, std::int32_t i) {
      fn(j, items_[static_cast<size_t>(first + i)]);
      progress_[j * threads_ + t].done.store(i + 1, std::memory_order_release);
    });
  }

  template <class F>
  void runThread(int t, F& fn) {
    const std::int32_t first = thread_begin_[static_cast<size_t>(t)];
    const std::int32_t last = thread_begin_[static_cast<size_t>(t) + 1];
    for (std::int32_t k = first; k < last; ++k) {
      const std::int32_t* need = need_.data() + static_cast<size_t>(k) * static_cast<size_t>(threads_);
      for (int u = 0; u < threads_; ++u)
        if (need[u] > 0) WorkerPool::waitAtLeast(progress_[u].done, need[u]);
      fn(items_[static_cast<size_t>(k)]);
      progress_[t].done.store(k - first + 1, std::memory_order_release);
    }
  }

  int threads_ = 0;  // 0: no schedule
  bool planned_ = false;
  std::vector<std::int32_t> thread_begin_;  // thread t's items: [thread_begin_[t], thread_begin_[t + 1])
  std::vector<FlowItem> items_;             // by thread, each thread's in the order it visits them
  std::vector<std::int32_t> need_;          // per item and thread u: items of u to wait for
  // Per item and thread u: items of u to wait for in the pass before, when
  // passes are interleaved: up to the last of u's items to touch one of
  // its bodies in the whole pass (and on its own thread, itself).
  std::vector<std::int32_t> prev_need_;
  std::unique_ptr<Progress[]> progress_;
  int progress_size_ = 0;

  // Planning, with scratch kept so that it allocates nothing once warm.
  struct Planned {
    FlowItem item;
    std::int32_t thread = 0, at = 0;  // its thread, and its place in that thread's visits
    std::int64_t finish = 0;          // when it ends in the plan's model of a pass
  };
  struct Run {
    std::int32_t thread = 0, begin = 0, end = 0;
  };
  void colourItems(const GraphProblem& p, std::int32_t colour, int dynamic_end);
  std::span<const std::int32_t> bodiesOf(std::int32_t item) const {
    const std::int32_t begin = item_body_begin_[static_cast<size_t>(item)];
    return {item_bodies_.data() + begin, static_cast<size_t>(item_body_begin_[static_cast<size_t>(item) + 1] - begin)};
  }
  std::int64_t ready(std::int32_t item, std::int32_t thread) const;
  std::int64_t evaluate(const std::vector<Run>& runs, std::int64_t& sum) const;
  void commit(std::int32_t colour, const std::vector<Run>& runs);
  // The n-th item a run's thread visits: the last thread walks its runs
  // from the end.
  std::int32_t visit(const Run& r, std::int32_t n) const {
    return r.thread > 0 && r.thread == threads_ - 1 ? r.end - 1 - n : r.begin + n;
  }

  std::vector<Planned> sequence_;              // every item, in the order planned
  std::vector<std::int32_t> need_sequence_;    // need_, in that order
  std::vector<std::int32_t> count_;            // per thread: items so far
  std::vector<std::int64_t> load_, free_;      // per thread: work so far, and when it is free
  std::vector<std::int32_t> last_;             // per body: the last item (in sequence_) to touch it
  std::vector<std::int32_t> last_at_;          // per body and thread: that thread's last item to touch it
  std::vector<std::int32_t> sequence_bodies_;  // every planned item's bodies, sequence_[q]'s from
  std::vector<std::int32_t> sequence_body_begin_;  // sequence_body_begin_[q]
  std::vector<std::int32_t> item_work_;        // the colour's items: work in eighths of a batch visit,
  std::vector<std::int32_t> item_body_begin_;  // and dynamic bodies
  std::vector<std::int32_t> item_bodies_;
  std::vector<Run> runs_, best_;
};

}  // namespace cairn
