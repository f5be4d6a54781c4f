// The split of a loop's items among threads by last time's cost
// (world/cost_split.hpp), fed with a known cost per item: its ranges cover
// the items in order, and they converge on equal shares of the cost.
#include "world/cost_split.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace cairn::detail {
namespace {

// The cost of items [begin, end) where item i costs cost[i].
double rangeCost(const std::vector<double>& cost, int begin, int end) {
  double sum = 0;
  for (int i = begin; i < end; ++i) sum += cost[static_cast<size_t>(i)];
  return sum;
}

void expectCover(const CostSplit& split, int count, int threads) {
  EXPECT_EQ(split.begin(0), 0);
  EXPECT_EQ(split.end(threads - 1), count);
  for (int t = 0; t < threads; ++t) EXPECT_LE(split.begin(t), split.end(t)) << "thread " << t;
  for (int t = 0; t + 1 < threads; ++t) EXPECT_EQ(split.end(t), split.begin(t + 1)) << "thread " << t;
}

TEST(CostSplit, FirstRangesAreEven) {
  CostSplit split;
  split.plan(1000, 4);
  expectCover(split, 1000, 4);
  for (int t = 0; t < 4; ++t) EXPECT_EQ(split.end(t) - split.begin(t), 250);
}

// A pyramid's pairs: the first 30% (lower rows, recycled) cost a third of
// the rest. Each round halves the distance to the balanced split, so
// after 12 rounds the threads' times agree to well under 1%.
TEST(CostSplit, RangesConvergeOnEqualSharesOfTheCost) {
  for (const int threads : {2, 3, 4}) {
    SCOPED_TRACE(threads);
    constexpr int kCount = 15000;
    std::vector<double> cost(kCount);
    for (int i = 0; i < kCount; ++i) cost[static_cast<size_t>(i)] = i < kCount * 3 / 10 ? 1.0 : 3.0;
    CostSplit split;
    std::vector<double> took(static_cast<size_t>(threads));
    for (int round = 0; round < 12; ++round) {
      split.plan(kCount, threads);
      expectCover(split, kCount, threads);
      for (int t = 0; t < threads; ++t) {
        took[static_cast<size_t>(t)] = rangeCost(cost, split.begin(t), split.end(t));
        split.record(t, took[static_cast<size_t>(t)]);
      }
    }
    const double total = rangeCost(cost, 0, kCount);
    for (int t = 0; t < threads; ++t) EXPECT_NEAR(took[static_cast<size_t>(t)], total / threads, 0.01 * total / threads) << "thread " << t;
  }
}

// A range that took no time (a thread that never ran it) leaves the split
// where it was; another thread count starts again from even ranges.
TEST(CostSplit, NoTimingKeepsTheSplitAndAnotherThreadCountStartsEven) {
  CostSplit split;
  split.plan(100, 2);
  split.record(0, 1.0);
  split.record(1, 3.0);
  split.plan(100, 2);
  const int moved = split.end(0);
  EXPECT_GT(moved, 50);  // the cheap first range grows
  split.record(0, 1.0);  // the second range not recorded
  split.plan(100, 2);
  EXPECT_EQ(split.end(0), moved);
  split.plan(90, 3);
  for (int t = 0; t < 3; ++t) EXPECT_EQ(split.end(t) - split.begin(t), 30);
}

}  // namespace
}  // namespace cairn::detail
