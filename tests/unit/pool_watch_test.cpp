// The rule by which a World sets its worker pool aside while the pool's
// threads lose their cores to other work (world/pool_watch.hpp), followed
// step by step with the lost waits given: the same rule the real scheduler
// feeds in tests/unit/solver_determinism_test.cpp.
#include "world/pool_watch.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace cairn {
namespace {

// Steps `steps` times; `lost(k)` is the count of lost waits a step on the
// pool reports, k counting the steps on the pool from 0. Returns the
// lengths of the runs alone, each closed by a step on the pool.
template <class Lost>
std::vector<int> runsAlone(PoolWatch& watch, int steps, Lost lost) {
  std::vector<int> runs;
  int alone = 0, on_pool = 0;
  for (int s = 0; s < steps; ++s) {
    if (!watch.startStep()) {
      ++alone;
      continue;
    }
    if (alone > 0) runs.push_back(alone);
    alone = 0;
    watch.endPoolStep(lost(on_pool++));
  }
  return runs;
}

TEST(PoolWatch, SitsOutSixteenStepsThenTwiceAsManyWhileTheCoresStayShared) {
  PoolWatch watch;
  const std::vector<int> runs = runsAlone(watch, 3100, [](int) { return PoolWatch::kPreemptedPerStep; });
  // 1 + 16 + 1 + 32 + ... + 1 + 1024 + 1 = 2,040 steps, then 1,024 alone at
  // a time: the eighth run closes at step 3,065.
  const std::vector<int> expected{16, 32, 64, 128, 256, 512, 1024, 1024};
  EXPECT_EQ(runs, expected);
}

TEST(PoolWatch, FewerLostWaitsThanTheThresholdKeepThePool) {
  PoolWatch watch;
  for (int s = 0; s < 100; ++s) {
    ASSERT_TRUE(watch.startStep()) << "step " << s;
    EXPECT_FALSE(watch.endPoolStep(PoolWatch::kPreemptedPerStep - 1));
  }
}

// Shared, shared, then a step on the pool that runs clear, then shared
// again: the run after the clear step is the first length again.
TEST(PoolWatch, AStepOnThePoolRunningClearStartsTheLengthsAgain) {
  PoolWatch watch;
  const std::vector<int> runs = runsAlone(watch, 1 + 16 + 1 + 32 + 1 + 1 + 16 + 1, [](int k) {
    return k == 2 ? PoolWatch::kPreemptedPerStep - 1 : PoolWatch::kPreemptedPerStep;
  });
  const std::vector<int> expected{16, 32, 16};
  EXPECT_EQ(runs, expected);
}

TEST(PoolWatch, ANewPoolStartsTheLengthsAgain) {
  PoolWatch watch;
  runsAlone(watch, 1 + 16 + 1 + 32 + 1, [](int) { return PoolWatch::kPreemptedPerStep; });  // the next run: 64
  watch.reset();
  EXPECT_EQ(runsAlone(watch, 1 + 16 + 1, [](int) { return PoolWatch::kPreemptedPerStep; }), std::vector<int>{16});
}

}  // namespace
}  // namespace cairn
