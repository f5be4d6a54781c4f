// The rules by which a World sets its worker pool aside while the pool's
// threads lose their cores to other work, or while steps alone run faster
// (world/pool_watch.hpp), followed step by step with the lost waits and
// the steps' times given: the same rules the real scheduler and clock feed
// in tests/unit/solver_determinism_test.cpp.
#include "world/pool_watch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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

// A machine where the k-th step on the pool takes `pool(k)` seconds and
// the k-th step alone `alone(k)` seconds, every step the same work and
// handing the pool a loop. Returns the runs alone as (first step, length, reason),
// step counting from 0.
struct RunAlone {
  int first, length;
  AloneReason why;
  bool operator==(const RunAlone&) const = default;
};
template <class PoolTime, class AloneTime>
std::vector<RunAlone> timedRunsBy(PoolWatch& watch, int steps, PoolTime pool, AloneTime alone, int work = 100,
                                  bool handed = true, int other_work_from = -1) {
  std::vector<RunAlone> runs;
  int on_pool = 0, alone_count = 0;
  for (int s = 0; s < steps; ++s) {
    const int w = other_work_from >= 0 && s >= other_work_from ? 2 * work : work;
    if (watch.startStep()) {
      watch.endPoolStep(0, handed, pool(on_pool++), w);
      continue;
    }
    const AloneReason why = watch.aside();
    if (runs.empty() || runs.back().first + runs.back().length != s || runs.back().why != why)
      runs.push_back({s, 0, why});
    ++runs.back().length;
    watch.endSoloStep(alone(alone_count++), w);
  }
  return runs;
}
// The same with every step on the pool `pool` seconds, every step alone
// `alone`.
std::vector<RunAlone> timedRuns(PoolWatch& watch, int steps, double pool, double alone, int work = 100,
                                bool handed = true, int other_work_from = -1) {
  return timedRunsBy(
      watch, steps, [pool](int) { return pool; }, [alone](int) { return alone; }, work, handed, other_work_from);
}

// Steps alone 20% faster than on the pool: the first probe comes after
// kProbeFirst + 3 pool steps (the fourth, which fills the ring, is the
// interval's first), 5 steps alone (its first not a sample); it finds no
// gain, so the pool
// sits out 16 steps, comes back (a wake-up step, 4 steps judged), is found
// not paying again and sits out twice as long, up to 256.
TEST(PoolWatch, AloneFasterSetsThePoolAsideForLongerEachTime) {
  constexpr int kProbe = 3 + PoolWatch::kProbeFirst;  // pool steps 0, 1, 2 fill the ring with the first decrement's
  PoolWatch watch;
  const std::vector<RunAlone> runs = timedRuns(watch, 700, 1.2, 1.0);
  std::vector<RunAlone> expected{{kProbe, 5, AloneReason::Probe}, {kProbe + 5, 16, AloneReason::NoGain}};
  int at = kProbe + 21;
  for (const int length : {32, 64, 128, 256, 256}) {
    at += 5;  // the wake-up step and 4 judged
    if (at >= 700) break;
    expected.push_back({at, std::min(length, 700 - at), AloneReason::NoGain});
    at += length;
  }
  EXPECT_EQ(runs, expected);
}

// The probes of a pool that pays, within `steps`: the first after
// kProbeFirst + 3 pool steps (pool steps 0, 1, 2 fill the ring with the
// first decrement's), each `length` steps alone, the next after a wake-up
// step, 3 more to fill the ring again (the fourth is the interval's
// first) and gap(k) pool steps, k counting the gaps from 0.
template <class Gap>
std::vector<RunAlone> probesOfAPoolThatPays(int steps, int length, Gap&& gap) {
  std::vector<RunAlone> expected;
  for (int at = 3 + PoolWatch::kProbeFirst, k = 0; at < steps; at += length + 1 + 3 + gap(k++))
    expected.push_back({at, length, AloneReason::Probe});
  return expected;
}

// The four-fold gaps: 4 kProbeFirst pool steps after the first probe,
// four times as many after each next, up to kProbeMost.
int fourFoldGap(int k) {
  int gap = 4 * PoolWatch::kProbeFirst;
  for (int i = 0; i < k; ++i) gap = std::min(4 * gap, PoolWatch::kProbeMost);
  return gap;
}

// The pool 5% faster: each probe of 5 steps finds it paying, and the next
// comes four times as many pool steps later, up to kProbeMost. (A probe's
// 5 steps at 5% over the pool's time cost under kProbeShare of 32 pool
// steps: the cost sets no longer gap here.)
TEST(PoolWatch, ThePoolPayingIsProbedFourTimesAsRarelyEachTime) {
  PoolWatch watch;
  const std::vector<RunAlone> runs = timedRuns(watch, 3000, 0.95, 1.0);
  EXPECT_EQ(runs, probesOfAPoolThatPays(3000, 5, fourFoldGap));
  EXPECT_EQ(runs.back().first - runs[runs.size() - 2].first, 5 + 1 + 3 + PoolWatch::kProbeMost);
}

// The pool twice as fast: a probe ends after 3 steps alone, the second
// sample making the steps alone's time (2.0) reach kSoloBetter of the
// pool's four steps (1.94), so that no later sample could turn the
// verdict. The 3 steps cost 3 pool steps' time beyond the pool's, which
// is kProbeShare (1%) of 300 pool steps: the next probe comes 300 pool
// steps later, not 32, and again (not 128), then the four-fold gaps take
// over (512, then kProbeMost).
TEST(PoolWatch, AFarFasterPoolIsProbedBrieflyAndSoRarelyThatProbesCostAHundredthOfItsTime) {
  PoolWatch watch;
  const std::vector<RunAlone> runs = timedRuns(watch, 3000, 0.5, 1.0);
  EXPECT_EQ(runs, probesOfAPoolThatPays(3000, 3, [](int k) { return std::max(300, fourFoldGap(k)); }));
  EXPECT_EQ(runs[1].first - runs[0].first, 3 + 1 + 3 + 300);
}

// A probe ends early only on a sealed verdict: with the pool 1.2 times as
// fast, three samples alone (3.0) are short of kSoloBetter of the pool's
// four (0.97 x 3.33 = 3.23), so the probe takes its 5 steps.
TEST(PoolWatch, AProbeWhoseVerdictIsOpenTakesAllItsSteps) {
  constexpr int kSteps = 3 + PoolWatch::kProbeFirst + 6;  // the first probe and one step after it
  PoolWatch watch;
  const std::vector<RunAlone> runs = timedRuns(watch, kSteps, 1.0 / 1.2, 1.0);
  EXPECT_EQ(runs, probesOfAPoolThatPays(kSteps, 5, fourFoldGap));
}

// Steps on the pool at an unsteady pace (0.3 and 0.8 seconds in turn,
// beyond kSteady of each other, as while pile-1000's boxes fall and its
// tree and pairs grow) give no verdict. A pool far faster than one thread
// is then not set 300 pool steps apart (as at a steady 0.5 above): its
// probes come at the four-fold gaps (each 4 steps: the third sample alone
// seals it, 3.0 against kSoloBetter of the pool's 2.2). And steps alone
// faster than such a pool (0.5 against 0.3 and 0.8, a mean of 0.55) do
// not set it aside.
TEST(PoolWatch, StepsAtAnUnsteadyPaceGiveNoVerdict) {
  const auto unsteady = [](int k) { return k % 2 == 0 ? 0.3 : 0.8; };
  PoolWatch watch;
  EXPECT_EQ(timedRunsBy(watch, 3000, unsteady, [](int) { return 1.0; }), probesOfAPoolThatPays(3000, 4, fourFoldGap));
  watch.reset();
  EXPECT_EQ(timedRunsBy(watch, 3000, unsteady, [](int) { return 0.5; }), probesOfAPoolThatPays(3000, 5, fourFoldGap));
}

// Unsteady steps alone likewise: the pool at a steady 1.2, alone 0.5 and
// 1.0 in turn (a mean of 0.75, far faster) keeps the pool.
TEST(PoolWatch, StepsAloneAtAnUnsteadyPaceGiveNoVerdict) {
  PoolWatch watch;
  const auto unsteady = [](int k) { return k % 2 == 0 ? 0.5 : 1.0; };
  for (const RunAlone& r : timedRunsBy(watch, 600, [](int) { return 1.2; }, unsteady)) EXPECT_EQ(r.why, AloneReason::Probe);
}

// Alone within 3% of the pool (kSoloBetter): the pool stays.
TEST(PoolWatch, AloneBarelyFasterKeepsThePool) {
  PoolWatch watch;
  for (const RunAlone& r : timedRuns(watch, 600, 1.0, 0.98)) EXPECT_EQ(r.why, AloneReason::Probe);
}

// A probe's first step alone reads what the pool's threads wrote last and
// runs slow (here twice as long as the steps alone after it): it is not a
// sample. The pool at 1.2, alone 1.0 after a first step of 2.0: counted,
// the first step would make alone 1.25 a step, slower than the pool;
// dropped, alone is 1.0 and the pool sits out.
TEST(PoolWatch, AProbesFirstStepAloneIsNotASample) {
  PoolWatch watch;
  for (int s = 0; s < 3 + PoolWatch::kProbeFirst; ++s) {
    ASSERT_TRUE(watch.startStep());
    watch.endPoolStep(0, true, 1.2, 100);
  }
  for (int s = 0; s < PoolWatch::kSample + 1; ++s) {
    ASSERT_FALSE(watch.startStep()) << "probe step " << s;
    EXPECT_EQ(watch.aside(), AloneReason::Probe);
    watch.endSoloStep(s == 0 ? 2.0 : 1.0, 100);
  }
  EXPECT_EQ(watch.aside(), AloneReason::NoGain);
  EXPECT_FALSE(watch.startStep());
}

// Steps that hand the pool nothing never lead to a probe; nor does a probe
// whose steps did twice the work of the pool's steps give a verdict (the
// work doubles at the probe's first step): the pool comes back until the
// next probe, 1 + 3 + 4 kProbeFirst pool steps later.
TEST(PoolWatch, StepsHandingNothingOrOfOtherWorkGiveNoVerdict) {
  constexpr int kProbe = 3 + PoolWatch::kProbeFirst;
  PoolWatch watch;
  EXPECT_TRUE(timedRuns(watch, 500, 1.2, 1.0, 100, false).empty());
  watch.reset();
  const int next_probe = kProbe + 5 + 1 + 3 + 4 * PoolWatch::kProbeFirst;
  EXPECT_EQ(timedRuns(watch, next_probe, 1.2, 1.0, 100, true, kProbe),
            (std::vector<RunAlone>{{kProbe, 5, AloneReason::Probe}}));
}

// Lost cores when the pool returns from a run alone for no gain: the lost
// cores' rule takes over (its run of 16), and after it the gain rule starts
// over with a probe once its ring is full again (a wake-up step, 4 pool
// steps), not with a verdict on the old samples.
TEST(PoolWatch, LostCoresTakeOverFromTheGainRule) {
  PoolWatch watch;
  for (int s = 0; s < 3 + PoolWatch::kProbeFirst; ++s) {
    ASSERT_TRUE(watch.startStep());
    watch.endPoolStep(0, true, 1.2, 100);
  }
  for (int s = 0; s < 5; ++s) {  // the probe, alone faster: no gain
    ASSERT_FALSE(watch.startStep());
    EXPECT_EQ(watch.aside(), AloneReason::Probe);
    watch.endSoloStep(1.0, 100);
  }
  EXPECT_EQ(watch.aside(), AloneReason::NoGain);
  for (int s = 0; s < 16; ++s) {
    ASSERT_FALSE(watch.startStep());
    watch.endSoloStep(1.0, 100);
  }
  ASSERT_TRUE(watch.startStep());
  EXPECT_TRUE(watch.endPoolStep(PoolWatch::kPreemptedPerStep, true, 1.2, 100));
  EXPECT_EQ(watch.aside(), AloneReason::LostCores);
  for (int s = 0; s < PoolWatch::kSoloFirst; ++s) {
    ASSERT_FALSE(watch.startStep());
    watch.endSoloStep(1.0, 100);
  }
  for (int s = 0; s < 4; ++s) {
    ASSERT_TRUE(watch.startStep());
    EXPECT_FALSE(watch.endPoolStep(0, true, 1.2, 100)) << "pool step " << s;
  }
  ASSERT_TRUE(watch.startStep());
  EXPECT_TRUE(watch.endPoolStep(0, true, 1.2, 100));
  EXPECT_EQ(watch.aside(), AloneReason::Probe);
}

}  // namespace
}  // namespace cairn
