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
// When a border item still waits, its thread runs the next of its items
// that is ready instead (up to kLookahead ahead: the next colour's items
// at the far end of its run share no body with it), and comes back to it.
// Out-of-order work hides the other thread's lag instead of waiting it
// out: on the 5,050-box pyramid it took about 1.5 ms of the 2.5 to 3 ms a
// step that the waits cost the solve on two threads (docs/performance.md,
// "Earlier: a look ahead in one island's flow, ..."). It needs what the
// in-order schedule could leave out: every item of its own thread that
// touched one of its bodies before it (per body, the last one), not only
// the latest of them.
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
// pipeline (pass_pipeline.hpp) runs its passes through it; the flow's
// threads (below) run theirs the same way, with a look ahead in the
// leading pass.
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
  // Items the last run() or runInterleaved() ran while an item before them
  // on their thread waited (runThreadInterleaved's look ahead).
  std::int64_t passedOver() const {
    std::int64_t n = 0;
    for (const Tally& t : tally_) n += t.passed_over;
    return n;
  }
  void reset() {
    threads_ = 0;
    planned_ = false;
  }

  // Runs fn(item) for every item on `pool` (whose thread count the plan
  // was made for): each thread its own items, each after the items, on any
  // thread, that touched its bodies before it (one pass of
  // runInterleaved).
  template <class F>
  void run(WorkerPool& pool, F&& fn) {
    runInterleaved(pool, 1, [&](int, const FlowItem& it) { fn(it); });
  }

  // Runs fn(j, item) for consecutive passes j = 0 .. passes - 1 over every
  // item, each thread its own items in every pass, interleaved as on one
  // thread (pass_pipeline.hpp): after each item of its first unfinished
  // pass, a thread runs its later passes' items as far as they are ready.
  // An item of pass j is ready when the items of pass j it waits for in
  // run() are done, and those of pass j - 1 that touch its bodies, on any
  // thread. Only the first unfinished pass waits, and it runs any ready
  // item of the next few instead (runThreadInterleaved); no wait can
  // deadlock: the earliest unfinished item of the lowest unfinished pass
  // waits for nothing.
  template <class F>
  void runInterleaved(WorkerPool& pool, int passes, F&& fn) {
    for (int k = 0; k < passes * threads_; ++k) progress_[k].done.store(0, std::memory_order_relaxed);
    for (Tally& t : tally_) t.passed_over = 0;
    pool.parallelFor(threads_, [&](int t, int) { runThreadInterleaved(t, passes, fn); });
  }

 private:
  struct alignas(64) Progress {
    std::atomic<std::int32_t> done{0};  // items of this thread finished in this pass
  };
  struct alignas(64) Tally {
    std::int64_t passed_over = 0;  // written by its thread alone, read after the run
  };

  // Whether thread u has done `count` of its items in pass j.
  bool reached(int j, int u, std::int32_t count) const {
    return progress_[j * threads_ + u].done.load(std::memory_order_acquire) >= count;
  }

  // How many of its next items of the leading pass a thread looks over
  // for one that is ready (runThreadInterleaved).
  static constexpr std::int32_t kLookahead = 8;

  // Thread t's share of `passes` interleaved passes (one, for run()).
  // The leading pass (its first unfinished one) runs the first of its next
  // kLookahead items that is ready, not only the next in order: an item
  // that waits for the other thread's border item of the colour before is
  // passed over while the items after it, which share no body with it,
  // run. Each body still sees its constraints in colour order, one at a
  // time (an item runs only after the items before it, on any thread, that
  // touch its bodies), so the bits are those of one thread. What a thread
  // makes known is the count of its items done without a gap (`pos`): a
  // thread that waits for one of a passed-over item's followers waits for
  // it too, which only delays. No wait can deadlock: the earliest
  // unfinished item, in the plan's order, of the lowest unfinished pass
  // is ready, and it is the first of its thread's window.
  template <class F>
  void runThreadInterleaved(int t, int passes, F& fn) {
    const std::int32_t first = thread_begin_[static_cast<size_t>(t)];
    const std::int32_t n = thread_begin_[static_cast<size_t>(t) + 1] - first;
    const size_t stride = items_.size();
    for (int j = 0; j < passes; ++j)
      std::fill_n(ran_.begin() + static_cast<std::ptrdiff_t>(static_cast<size_t>(j) * stride + static_cast<size_t>(first)), n,
                  std::uint8_t{0});
    const auto ran = [&](int j, std::int32_t i) -> std::uint8_t& {
      return ran_[static_cast<size_t>(j) * stride + static_cast<size_t>(first + i)];
    };
    std::int32_t pos[kMaxOverlappedPasses] = {};  // per pass: items done without a gap
    const auto ready = [&](int j, std::int32_t i) {
      const size_t k = static_cast<size_t>(first + i) * static_cast<size_t>(threads_);
      for (int u = 0; u < threads_; ++u) {
        const std::int32_t same = need_[k + static_cast<size_t>(u)];
        const std::int32_t before = j > 0 ? prev_need_[k + static_cast<size_t>(u)] : 0;
        if (u == t) {
          if (j > 0 && before > pos[j - 1]) return false;  // this thread's own pass before
          continue;
        }
        if (same > 0 && !reached(j, u, same)) return false;
        if (before > 0 && !reached(j - 1, u, before)) return false;
      }
      // This thread's items before it that touch its bodies, per body the
      // last of them: run, or within the count done without a gap (all
      // of them are for the next item in order, the trailing passes' only
      // kind).
      if (i == pos[j]) return true;
      const size_t item = static_cast<size_t>(first + i);
      for (std::int32_t q = own_prev_begin_[item]; q < own_prev_begin_[item + 1]; ++q) {
        const std::int32_t own = own_prev_[static_cast<size_t>(q)];
        if (own >= pos[j] && !ran(j, own)) return false;
      }
      return true;
    };
    const auto publish = [&](int j) {
      std::int32_t p = pos[j];
      while (p < n && ran(j, p)) ++p;
      if (p == pos[j]) return;
      pos[j] = p;
      progress_[j * threads_ + t].done.store(p, std::memory_order_release);
    };
    int spin = 0;
    for (int lead = 0; lead < passes;) {
      if (pos[lead] == n) {
        ++lead;
        continue;
      }
      bool ran_one = false;
      const std::int32_t window = std::min(n, pos[lead] + kLookahead);
      for (std::int32_t i = pos[lead]; i < window && !ran_one; ++i) {
        if (ran(lead, i) || !ready(lead, i)) continue;
        fn(lead, items_[static_cast<size_t>(first + i)]);
        ran(lead, i) = 1;
        ran_one = true;
        if (i != pos[lead]) ++tally_[static_cast<size_t>(t)].passed_over;
      }
      if (ran_one) {
        publish(lead);
        spin = 0;
      } else {
        WorkerPool::waitRound(spin++);
      }
      for (int j = lead + 1; j < passes; ++j)
        while (pos[j] < n && ready(j, pos[j])) {
          fn(j, items_[static_cast<size_t>(first + pos[j])]);
          ran(j, pos[j]) = 1;
          publish(j);
        }
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
  // Per item, from own_prev_begin_[k] to own_prev_begin_[k + 1]: for each
  // of its bodies that an item before it on its thread touched, the place
  // in the thread's order of the last such item (each place once).
  std::vector<std::int32_t> own_prev_begin_, own_prev_;
  // Per pass and item: whether it has run (each thread writes its own).
  std::vector<std::uint8_t> ran_;
  std::unique_ptr<Progress[]> progress_;
  std::vector<Tally> tally_;  // per thread
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
  std::vector<std::int32_t> own_prev_sequence_;  // own_prev_, in that order: sequence_[q]'s from
  std::vector<std::int32_t> own_prev_sequence_begin_;  // own_prev_sequence_begin_[q]
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
