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
#include <thread>

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

// A pool kept warm (as a World keeps its own through a step) never lets a
// worker sleep however long the calling thread works alone between loops,
// and every loop still runs each chunk once; once it is let go, the
// workers go back to sleep and a later loop still wakes them.
TEST(WorkerPool, AWarmPoolsWorkersWaitAwakeBetweenLoopsAndSleepOnceLetGo) {
  WorkerPool pool(2);
  const auto runLoop = [&] {
    std::atomic<int> items{0};
    pool.parallelFor(64, [&](int begin, int end) { items.fetch_add(end - begin); });
    EXPECT_EQ(items.load(), 64);
  };
  const auto sleepsWithin = [&](std::int64_t above, std::chrono::milliseconds limit) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (pool.sleeps() <= above && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return pool.sleeps() > above;
  };
  // Unwarmed, an idle worker sleeps after its bounded wait (well under a
  // second even when each of its yields hands the core away for a slice).
  runLoop();
  ASSERT_TRUE(sleepsWithin(0, std::chrono::seconds(10)));
  pool.keepWarm(true);  // wakes the sleeper
  const std::int64_t before = pool.sleeps();
  for (int k = 0; k < 5; ++k) {
    runLoop();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // the caller alone, far past the bounded wait
  }
  EXPECT_EQ(pool.sleeps(), before);
  pool.keepWarm(false);
  EXPECT_TRUE(sleepsWithin(before, std::chrono::seconds(10)));
  runLoop();
}

}  // namespace
}  // namespace cairn
