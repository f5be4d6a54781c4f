// When the step sets its worker pool aside: the rules, apart from the
// threads and clocks that feed them, so that they can be followed step by
// step. Results do not depend on the thread count
// (tests/unit/solver_determinism_test.cpp), so neither do they on these.
//
// Lost cores. A pool whose threads lose their cores to other work in a
// step (WorkerPool::takePreemptedWaits) runs the step slower than one
// thread: its loops hand work between threads every few microseconds, and
// each handover waits for a thread that is not running. So after a step
// with kPreemptedPerStep such waits the pool is set aside and the world
// steps on the calling thread alone for kSoloFirst steps, twice as many
// each time the pool is found sharing its cores again (up to kSoloMost),
// then takes it back to try. A step on the pool not found sharing starts
// the lengths again at kSoloFirst.
//
// No gain. Two cores of their own can still make a step slower than one:
// each handover moves the bodies' and rows' cache lines between the
// cores, and what that costs is the machine's (on one 2-CPU virtual
// machine an awake pyramid-20 stepped 1.2 to 1.65 times slower on two
// threads than on one, docs/performance.md, "Threads"). So the watch measures the
// pool's gain on the scene as it runs: after kProbeFirst steps that
// handed the pool a loop, it steps alone for a while (a probe) and
// compares the wall time of kSample steps alone with that of the kSample
// pool steps before. A run alone's first step is not one of them: it
// reads the bodies, rows and contacts the pool's threads wrote last, from
// the other cores' caches, and ran 1.3 times as long as the steps alone
// after it on an awake pyramid-20 (1.38 against 1.05 ms); counted, it
// made a pool that lost 8% look as fast as the calling thread alone
// (pile-1000's awake steps, docs/performance.md, "Threads"). So a probe is
// kSample + 1 steps.
// Where the steps alone took less than kSoloBetter of the pool's time, the
// pool sits out kNoGainFirst steps, twice as many each time it is found
// not paying again (up to kNoGainMost), and is judged again on its
// kSample steps after each return. Where it pays, the next probe comes
// four times as many steps later (up to kProbeMost), and no sooner than
// its cost allows: a probe's steps alone are what the rule costs a scene
// whose pool pays, their time beyond the pool's is held to kProbeShare of
// the pool's time until the next probe, so the wider the pool's margin the
// rarer the probes (a pool twice as fast as one thread is probed 300 pool
// steps apart at first, not 32; one 5% faster as before). A probe
// also ends as soon as its verdict is sealed: once its steps alone so far
// took kSoloBetter of the pool's kSample steps, no step alone after them
// can make the steps alone the faster (the same verdict the whole probe
// would give, a step or two sooner). Steps are compared only
// when they did about the same work (rows within kSameWork of each other)
// at a steady pace (the pool's samples within kSteady of each other, and
// the samples alone likewise), the pool's only when it was handed a loop,
// and never the first step on a pool back from sitting out (its workers
// wake from sleep). The pace matters where the rows do not show the work:
// pile-1000's boxes fall through their first 18 steps with no contact at
// all, each step 0.16 to 1.28 ms on two threads as its tree and pairs
// grow; a probe there found its steps alone 1.47 times as long as the
// pool's and set the next probe 190 pool steps later, past the 162 awake
// steps, where what the pool gains is the machine's (9% lost in one
// spell, 14% gained in another: docs/performance.md, "Now: bodies
// written back as whole lines, ...").
#pragma once

#include "cairn/stats.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace cairn {

// Which rules may set the pool aside: none, the lost cores' alone, or both.
enum class PoolRules { None, LostCores, All };

// A run length that starts at `first` and grows `factor` times with each
// take, up to `most` (the runs alone and the gaps between probes below).
class GrowingLength {
 public:
  constexpr GrowingLength(int first, int factor, int most) : first_(first), factor_(factor), most_(most), next_(first) {}
  int take() {
    const int n = next_;
    next_ = std::min(factor_ * next_, most_);
    return n;
  }
  void reset() { next_ = first_; }

 private:
  int first_, factor_, most_, next_;
};

class PoolWatch {
 public:
  static constexpr std::int64_t kPreemptedPerStep = 8;
  static constexpr int kSoloFirst = 16;
  static constexpr int kSoloMost = 1024;
  static constexpr int kSample = 4;
  static constexpr int kProbeFirst = 8;
  static constexpr int kProbeMost = 1024;
  static constexpr int kNoGainFirst = 16;
  static constexpr int kNoGainMost = 256;
  static constexpr double kSoloBetter = 0.97;
  static constexpr double kSameWork = 1.1;
  static constexpr double kSteady = 1.5;
  static constexpr double kProbeShare = 0.01;

  // Before a step: whether it runs on the pool (false: on the calling
  // thread alone, one of the steps sat out).
  bool startStep() {
    if (solo_steps_ == 0) return true;
    --solo_steps_;
    return false;
  }

  // After a step on the pool, given the waits in it that lost their core,
  // whether a loop was handed to the pool, the step's wall time and its
  // work (rows): whether the pool is set aside from the next step on.
  bool endPoolStep(std::int64_t preempted_waits, bool handed = false, double seconds = 0, int work = 0) {
    if (preempted_waits >= kPreemptedPerStep) {
      solo_steps_ = lost_cores_run_.take();
      aside_ = AloneReason::LostCores;
      pool_count_ = 0;
      judging_ = false;
      wake_ = true;
      return true;
    }
    lost_cores_run_.reset();
    aside_ = AloneReason::None;
    if (!handed) return false;  // a step that hands nothing says nothing about the pool's gain
    if (wake_) {
      wake_ = false;
      return false;
    }
    pool_[static_cast<size_t>(pool_count_++ % kSample)] = {seconds, work};
    if (pool_count_ < kSample) return false;
    if (judging_) {
      judging_ = false;
      if (soloBetter()) return setAsideForNoGain();
      no_gain_run_.reset();
      probe_gap_.reset();
      to_probe_ = kProbeFirst;
      return false;
    }
    if (--to_probe_ > 0) return false;
    solo_steps_ = kSample + 1;
    solo_count_ = 0;
    first_alone_ = true;
    aside_ = AloneReason::Probe;
    return true;
  }

  // After a step alone: its wall time and work. The pool comes back at
  // the next startStep unless this ends a probe that found no gain.
  void endSoloStep(double seconds, int work) {
    if (aside_ == AloneReason::LostCores || aside_ == AloneReason::None) return;  // shared cores' times say nothing
    if (first_alone_) first_alone_ = false;  // the pool's data still in the other cores' caches: not a sample
    else solo_[static_cast<size_t>(solo_count_++ % kSample)] = {seconds, work};
    if (aside_ == AloneReason::Probe && poolPaysWhateverFollows()) solo_steps_ = 0;
    if (solo_steps_ > 0) return;
    if (aside_ == AloneReason::Probe && solo_count_ >= kSample && soloBetter()) {
      setAsideForNoGain();
      return;
    }
    if (aside_ == AloneReason::Probe) {
      to_probe_ = std::max(probe_gap_.take(), gapForCost());
    } else {
      judging_ = true;
    }
    pool_count_ = 0;
    wake_ = true;
    aside_ = AloneReason::None;
  }

  // Why the steps alone run alone now (None while on the pool).
  AloneReason aside() const { return aside_; }

  // A pool made anew (another thread count): everything starts again.
  void reset() { *this = PoolWatch{}; }

 private:
  struct Sample {
    double seconds = 0;
    int work = 0;
  };

  // Whether the last kSample steps alone took less than kSoloBetter of the
  // last kSample pool steps' time, all of them about the same work.
  bool soloBetter() const {
    if (solo_count_ < kSample) return false;
    const Taken t = taken();
    return t.comparable && t.solo < kSoloBetter * t.pool;
  }

  // The pool's latest kSample steps and the steps alone sampled so far (up
  // to kSample): the seconds of each summed, and whether all of them did
  // about the same work, the pool's and the steps alone each at a steady
  // pace.
  struct Taken {
    double pool = 0, solo = 0;
    bool comparable = false;
  };
  // The samples' seconds summed; their work and seconds widen the ranges.
  struct Range {
    int least_work, most_work;
    double least_seconds, most_seconds;
  };
  static double sum(const std::array<Sample, kSample>& ring, int n, Range& r) {
    double total = 0;
    for (int k = 0; k < n; ++k) {
      const Sample& x = ring[static_cast<size_t>(k)];
      r.least_work = std::min(r.least_work, x.work);
      r.most_work = std::max(r.most_work, x.work);
      r.least_seconds = std::min(r.least_seconds, x.seconds);
      r.most_seconds = std::max(r.most_seconds, x.seconds);
      total += x.seconds;
    }
    return total;
  }
  static Range rangeOf(const Sample& x) { return {x.work, x.work, x.seconds, x.seconds}; }
  static bool steady(const Range& r) { return r.most_seconds <= kSteady * r.least_seconds; }
  Taken taken() const {
    Taken t;
    if (pool_count_ < kSample || solo_count_ == 0) return t;
    Range pool = rangeOf(pool_[0]), solo = rangeOf(solo_[0]);
    t.pool = sum(pool_, kSample, pool);
    t.solo = sum(solo_, std::min(solo_count_, kSample), solo);
    const int least = std::min(pool.least_work, solo.least_work), most = std::max(pool.most_work, solo.most_work);
    t.comparable = double(most) <= kSameWork * double(least) && steady(pool) && steady(solo);
    return t;
  }

  // A probe short of kSample steps alone whose steps so far already took
  // kSoloBetter of the pool's kSample: the steps alone cannot be found the
  // faster, and the pool comes back (after no verdict as well).
  bool poolPaysWhateverFollows() const {
    if (solo_count_ == 0 || solo_count_ >= kSample) return false;
    const Taken t = taken();
    return t.pool > 0 && t.solo >= kSoloBetter * t.pool;
  }

  // After a probe that found the pool paying: the pool steps until the
  // next probe for the probe's steps alone (its samples and its first
  // step) to cost no more, beyond the pool's time, than kProbeShare of the
  // pool's time until then (0 when the probe's steps cannot be compared
  // with the pool's).
  int gapForCost() const {
    const Taken t = taken();
    if (!t.comparable || t.pool <= 0) return 0;
    const double ratio = (t.solo / solo_count_) / (t.pool / kSample);  // a probe takes at most kSample samples
    const double gap = std::ceil(double(solo_count_ + 1) * (ratio - 1) / kProbeShare);
    return gap >= kProbeMost ? kProbeMost : std::max(0, static_cast<int>(gap));
  }

  bool setAsideForNoGain() {
    solo_steps_ = no_gain_run_.take();
    solo_count_ = 0;
    first_alone_ = aside_ != AloneReason::Probe;  // straight after a probe the data is this thread's already
    aside_ = AloneReason::NoGain;
    return true;
  }

  int solo_steps_ = 0;  // steps still to sit out
  GrowingLength lost_cores_run_{kSoloFirst, 2, kSoloMost};  // the runs alone when the pool is found sharing its cores
  AloneReason aside_ = AloneReason::None;
  std::array<Sample, kSample> pool_{}, solo_{};  // the latest steps on the pool and alone, as rings
  int pool_count_ = 0, solo_count_ = 0;          // samples taken since the rings were last emptied
  int to_probe_ = kProbeFirst;                   // pool steps until the next probe
  GrowingLength probe_gap_{4 * kProbeFirst, 4, kProbeMost};  // pool steps between the probes after the first
  GrowingLength no_gain_run_{kNoGainFirst, 2, kNoGainMost};  // the runs alone when the pool is found not paying
  bool judging_ = false;                         // back from a run alone for no gain: judge the pool again
  bool first_alone_ = false;                     // the next step alone is a run's first after pool steps
  bool wake_ = false;                            // the next pool step is its workers' wake-up
};

}  // namespace cairn
