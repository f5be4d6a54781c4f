// When the step sets its worker pool aside: the rule, apart from the
// threads and clocks that feed it, so that it can be followed step by step.
//
// A pool whose threads lose their cores to other work in a step
// (WorkerPool::takePreemptedWaits) runs the step slower than one thread:
// its loops hand work between threads every few microseconds, and each
// handover waits for a thread that is not running. So after a step with
// kPreemptedPerStep such waits the pool is set aside and the world steps
// on the calling thread alone for kSoloFirst steps, twice as many each
// time the pool is found sharing its cores again (up to kSoloMost), then
// takes it back to try. A step on the pool not found sharing starts the
// lengths again at kSoloFirst. Results do not depend on the thread count
// (tests/unit/solver_determinism_test.cpp), so neither do they on this.
#pragma once

#include <algorithm>
#include <cstdint>

namespace cairn {

class PoolWatch {
 public:
  static constexpr std::int64_t kPreemptedPerStep = 8;
  static constexpr int kSoloFirst = 16;
  static constexpr int kSoloMost = 1024;

  // Before a step: whether it runs on the pool (false: on the calling
  // thread alone, one of the steps sat out).
  bool startStep() {
    if (solo_steps_ == 0) return true;
    --solo_steps_;
    return false;
  }

  // After a step on the pool, given the waits in it that lost their core:
  // whether the pool is set aside from the next step on.
  bool endPoolStep(std::int64_t preempted_waits) {
    if (preempted_waits < kPreemptedPerStep) {
      solo_length_ = kSoloFirst;
      return false;
    }
    solo_steps_ = solo_length_;
    solo_length_ = std::min(2 * solo_length_, kSoloMost);
    return true;
  }

  // A pool made anew (another thread count): the lengths start again.
  void reset() { *this = PoolWatch{}; }

 private:
  int solo_steps_ = 0;            // steps still to sit out
  int solo_length_ = kSoloFirst;  // the next run alone, when the pool is set aside again
};

}  // namespace cairn
