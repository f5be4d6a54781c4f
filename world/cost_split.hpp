// Contiguous ranges of a loop's items, one per thread, sized by what each
// range cost the last time, so that the threads end together.
//
// collide's pairs do not cost alike: a pair whose manifold is recycled
// takes a fraction of one that needs the narrowphase, and a pyramid
// recycles its lower rows' pairs far more than its upper rows'. With even
// halves, one thread of the 5,050-box pyramid spent 5.7 ms on its pairs
// while the other spent 4.6 and then waited. The cost moves slowly from
// step to step, so last step's time per item over each range, taken as
// the density of the cost, places the next split points at equal shares
// (halfway from the old points, so that one noisy timing does not make
// the split swing). Which thread runs which items never changes the
// results: each range's output is joined in item order.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace cairn::detail {

class CostSplit {
 public:
  // Plans the ranges of `count` items for `threads` threads from the last
  // recorded costs (even ranges the first time or after the thread count
  // changed).
  void plan(int count, int threads) {
    const auto n = static_cast<size_t>(threads);
    if (fraction_.size() != n + 1) {
      fraction_.assign(n + 1, 0);
      for (size_t t = 0; t <= n; ++t) fraction_[t] = static_cast<double>(t) / static_cast<double>(n);
      seconds_.assign(n, 0);
    } else if (std::all_of(seconds_.begin(), seconds_.end(), [](double s) { return s > 0; })) {
      rebalance();
    }
    bounds_.assign(n + 1, 0);
    for (size_t t = 0; t <= n; ++t) bounds_[t] = static_cast<int>(std::lround(fraction_[t] * count));
    std::fill(seconds_.begin(), seconds_.end(), 0.0);
  }
  int begin(int thread) const { return bounds_[static_cast<size_t>(thread)]; }
  int end(int thread) const { return bounds_[static_cast<size_t>(thread) + 1]; }
  // What thread `thread`'s range took.
  void record(int thread, double seconds) { seconds_[static_cast<size_t>(thread)] = seconds; }

 private:
  // New split points at equal shares of the cost, the cost spread evenly
  // over each old range; then halfway there from the old points.
  void rebalance() {
    const size_t n = seconds_.size();
    double total = 0;
    for (const double s : seconds_) total += s;
    std::vector<double>& next = scratch_;
    next.assign(n + 1, 0);
    next[n] = 1;
    size_t range = 0;
    double before = 0;  // the cost of the ranges before `range`
    for (size_t k = 1; k < n; ++k) {
      const double share = total * static_cast<double>(k) / static_cast<double>(n);
      while (range + 1 < n && before + seconds_[range] < share) before += seconds_[range++];
      const double within = std::clamp((share - before) / seconds_[range], 0.0, 1.0);
      next[k] = fraction_[range] + within * (fraction_[range + 1] - fraction_[range]);
    }
    for (size_t k = 1; k < n; ++k) fraction_[k] = (fraction_[k] + next[k]) / 2;
  }

  std::vector<double> fraction_;  // threads + 1 split points in [0, 1], ascending
  std::vector<double> seconds_;   // per thread, its range's time at the last loop
  std::vector<double> scratch_;
  std::vector<int> bounds_;
};

}  // namespace cairn::detail
