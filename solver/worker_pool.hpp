// A small pool of worker threads for the step's parallel loops.
//
// The step splits its work into loops whose items are independent (the
// constraints of one graph colour, the bodies to integrate, the pairs to
// collide), many of them a few microseconds long, with a barrier after
// each. A general task scheduler (oneTBB's parallel_for) costs a few
// microseconds per loop for its task bookkeeping, as much as the small
// loops themselves; Box2D v3 and Jolt keep their workers spinning between
// stages for the same reason. So: persistent workers, a loop handed over
// through one atomic generation counter, contiguous static chunks (no
// stealing: the items of a loop cost about the same), and a spin-then-wait
// barrier. Results never depend on the split: every loop writes disjoint
// data, and the reductions the step needs are done afterwards in a fixed
// order (docs/performance.md, "Threads").
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace cairn {

class WorkerPool {
 public:
  // `threads` >= 1 counts the calling thread: threads - 1 workers start.
  explicit WorkerPool(int threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int threads() const { return threads_; }

  // While warm, idle workers keep waiting round after round (a pause, then
  // a yield of the core) instead of going to sleep, and turning it on
  // wakes those asleep. The World keeps its pool warm through a step that
  // follows one with a loop handed over: a step's loops come tens of
  // microseconds to milliseconds apart, the spin-then-sleep wait below
  // outlasts only the shortest gaps, and each loop after a longer one paid
  // a worker's wake-up (docs/performance.md, "Earlier: a warm pool"). Between
  // steps the workers go back to the bounded wait and sleep.
  void keepWarm(bool on);
  // Loops handed to the workers since takeLoops was last called.
  std::int64_t loops() const { return loops_; }
  // Loops handed to the workers since the last call (parallelFor calls
  // with more than one chunk); starts the count again.
  std::int64_t takeLoops() {
    const std::int64_t n = loops_;
    loops_ = 0;
    return n;
  }
  // How many times a worker has gone to sleep since the pool started (for
  // tests of keepWarm).
  std::int64_t sleeps() const { return sleeps_.load(std::memory_order_relaxed); }

  // Waits inside the pool's loops (on any of its threads) whose yield gave
  // the core to another task for longer than kPreemptedYield: the pool's
  // threads share their cores with other work. Each loop's threads hand
  // work to each other every few microseconds, so a thread that is not
  // running stalls the others for a scheduler slice (milliseconds) at each
  // handover: on a 2-core machine with two other busy processes, an
  // awake pyramid-20 stepped 24 times slower on two threads than on one.
  // Returns the count since the last call and starts it again.
  // While lost cores are simulated (simulateLostCores, for tests), every
  // call answers as if all of the pool's waits had lost their cores.
  std::int64_t takePreemptedWaits() {
    const std::int64_t n = preempted_.exchange(0, std::memory_order_relaxed);
    return simulated_lost_cores_.load(std::memory_order_relaxed) ? std::numeric_limits<std::int64_t>::max() : n;
  }
  // For tests of what follows a lost core (a World stepping alone, the
  // bench's note of it) without depending on which steps the machine's
  // scheduler takes the core from: process-wide, while `on`.
  static void simulateLostCores(bool on) { simulated_lost_cores_.store(on, std::memory_order_relaxed); }
  // 0 on the thread that calls parallelFor, 1 .. threads - 1 on the workers.
  static int currentThread();

  // Round `spin` (from 0) of a wait for another thread: a pause for the
  // first rounds, then a yield of the core, so that on a machine with no
  // core to spare the thread waited for can run. A yield during a loop's
  // work (waitAtLeast, the barrier after a loop) that gives the core to
  // another task for a while is counted: preemptedWaits().
  static void waitRound(int spin);
  // Waits, round after round, until `counter` (read with acquire order)
  // holds at least `value`; returns the last value read.
  static std::int32_t waitAtLeast(const std::atomic<std::int32_t>& counter, std::int32_t value);

  // Calls fn(begin, end) on contiguous chunks of [0, count), one per thread
  // (fewer when count is small), and returns when all are done. Not
  // re-entrant: fn must not call parallelFor.
  template <class F>
  void parallelFor(int count, F&& fn) {
    if (count <= 0) return;
    const int chunks = count < threads_ ? count : threads_;
    if (chunks == 1) {
      fn(0, count);
      return;
    }
    Job job;
    job.count = count;
    job.chunks = chunks;
    using Fn = std::remove_reference_t<F>;
    job.ctx = const_cast<void*>(static_cast<const void*>(&fn));
    job.call = [](void* ctx, int b, int e) { (*static_cast<Fn*>(ctx))(b, e); };
    run(job);
  }

 private:
  struct Job {
    int count = 0, chunks = 0;
    void* ctx = nullptr;
    void (*call)(void*, int, int) = nullptr;
  };
  void run(const Job& job);
  void workerLoop(int index);
  void doChunk(const Job& job, int chunk);

  int threads_;
  std::vector<std::thread> workers_;
  Job job_;
  // A new job bumps generation_; idle workers spin, yield, then sleep on
  // wake_ (unless warm_), whose mutex orders the bump and warm_ against a
  // worker's last look before sleeping, so no job is missed.
  std::atomic<std::uint64_t> generation_{0};
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  std::atomic<int> remaining_{0};
  std::atomic<bool> stop_{false};
  std::atomic<bool> warm_{false};
  std::atomic<std::int64_t> sleeps_{0};
  std::int64_t loops_ = 0;  // the calling thread's own count
  std::atomic<std::int64_t> preempted_{0};
  static inline std::atomic<bool> simulated_lost_cores_{false};
};

}  // namespace cairn
