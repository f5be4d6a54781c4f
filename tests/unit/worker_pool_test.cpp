// The worker pool notices when its threads lose their cores to other work
// (solver/worker_pool.hpp, takePreemptedWaits), the signal on which a World
// sets its pool aside (world/world_step.cpp). The busy machine is made
// certain by pinning the pool's threads to one core: a thread that waits
// for another then yields the core to it, and gets it back only when the
// other has run for a while.
#include "solver/worker_pool.hpp"
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <sched.h>

#include <atomic>
#include <chrono>

namespace cairn {
namespace {

TEST(WorkerPool, AWaitForAThreadOnTheSameCoreIsCountedAsPreempted) {
  const test::OneCore pinned;  // the pool's threads start on the caller's core
  WorkerPool pool(2);
  EXPECT_EQ(pool.takePreemptedWaits(), 0);
  // Chunk 0 (the calling thread) returns at once; chunk 1 (the worker)
  // computes for 20 ms, so the caller waits for it at the barrier, each
  // yield handing the core to the worker for a scheduler slice.
  std::atomic<double> sink{0};
  pool.parallelFor(2, [&](int begin, int) {
    if (begin == 0) return;
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(20);
    double x = 1;
    while (std::chrono::steady_clock::now() < until) x = x * 1.0000001 + 1e-9;
    sink.store(x);
  });
  EXPECT_GT(pool.takePreemptedWaits(), 0);
  EXPECT_EQ(pool.takePreemptedWaits(), 0);  // taken: counted from zero again
}

}  // namespace
}  // namespace cairn
