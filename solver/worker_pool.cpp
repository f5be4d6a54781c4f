#include "solver/worker_pool.hpp"

#include <chrono>

namespace cairn {

namespace {
thread_local int t_thread_index = 0;
// The pool whose loop this thread is running (a worker's own pool, or the
// pool the calling thread has handed a loop to), for the count of waits
// that lost the core; null outside a loop.
thread_local WorkerPool* t_pool = nullptr;

// A yield that returns after this long ran another task on the core: on an
// idle core sched_yield returns in about a microsecond.
constexpr auto kPreemptedYield = std::chrono::microseconds(50);

// Spins this many times on an atomic before yielding, and yields this many
// times before blocking on it: a loop of the step usually arrives within a
// few microseconds of the last one, and when the machine has fewer free
// cores than threads a yielding waiter hands its core to the thread it
// waits for instead of spinning out its time slice.
constexpr int kSpins = 256;
constexpr int kYields = 64;

}  // namespace

void WorkerPool::waitRound(int spin) {
  if (spin < kSpins) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    return;
  }
  if (!t_pool) {
    std::this_thread::yield();
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  std::this_thread::yield();
  if (std::chrono::steady_clock::now() - start > kPreemptedYield) t_pool->preempted_.fetch_add(1, std::memory_order_relaxed);
}

std::int32_t WorkerPool::waitAtLeast(const std::atomic<std::int32_t>& counter, std::int32_t value) {
  std::int32_t now = counter.load(std::memory_order_acquire);
  for (int spin = 0; now < value; ++spin) {
    waitRound(spin);
    now = counter.load(std::memory_order_acquire);
  }
  return now;
}

WorkerPool::WorkerPool(int threads) : threads_(threads < 1 ? 1 : threads) {
  workers_.reserve(static_cast<size_t>(threads_ - 1));
  for (int i = 1; i < threads_; ++i) workers_.emplace_back([this, i] { workerLoop(i); });
}

WorkerPool::~WorkerPool() {
  {
    const std::lock_guard<std::mutex> lock(wake_mutex_);
    stop_.store(true, std::memory_order_release);
    generation_.fetch_add(1, std::memory_order_acq_rel);
  }
  wake_.notify_all();
  for (auto& t : workers_) t.join();
}

int WorkerPool::currentThread() { return t_thread_index; }

void WorkerPool::keepWarm(bool on) {
  if (!on) {
    warm_.store(false, std::memory_order_relaxed);
    return;
  }
  {
    const std::lock_guard<std::mutex> lock(wake_mutex_);
    warm_.store(true, std::memory_order_relaxed);
  }
  wake_.notify_all();
}

void WorkerPool::doChunk(const Job& job, int chunk) {
  // Chunk c covers [c n / k, (c + 1) n / k): contiguous and balanced.
  const long n = job.count, k = job.chunks;
  const int begin = static_cast<int>(chunk * n / k), end = static_cast<int>((chunk + 1) * n / k);
  if (end > begin) job.call(job.ctx, begin, end);
}

void WorkerPool::run(const Job& job) {
  ++loops_;
  job_ = job;
  // Every worker reports back, busy or not, so none still reads job_ when
  // the next loop overwrites it.
  remaining_.store(threads_ - 1, std::memory_order_relaxed);
  {
    // Under the mutex, so a worker between its last look and its sleep
    // cannot miss the new generation.
    const std::lock_guard<std::mutex> lock(wake_mutex_);
    generation_.fetch_add(1, std::memory_order_acq_rel);
  }
  wake_.notify_all();
  t_pool = this;
  doChunk(job_, 0);
  for (int spin = 0; remaining_.load(std::memory_order_acquire) != 0; ++spin) waitRound(spin);
  t_pool = nullptr;
}

void WorkerPool::workerLoop(int index) {
  t_thread_index = index;
  // The generation at construction, not at this thread's start: a job
  // posted before the thread first runs must still be seen as new.
  std::uint64_t seen = 0;
  for (;;) {
    std::uint64_t now = generation_.load(std::memory_order_acquire);
    // While warm the rounds go on (their count held at the yields'), else
    // they end in a sleep.
    for (int spin = 0; now == seen && (spin < kSpins + kYields || warm_.load(std::memory_order_relaxed));) {
      waitRound(spin);
      if (spin < kSpins + kYields) ++spin;
      now = generation_.load(std::memory_order_acquire);
    }
    if (now == seen) {
      std::unique_lock<std::mutex> lock(wake_mutex_);
      if (generation_.load(std::memory_order_acquire) == seen && !warm_.load(std::memory_order_relaxed))
        sleeps_.fetch_add(1, std::memory_order_relaxed);
      wake_.wait(lock, [&] {
        return generation_.load(std::memory_order_acquire) != seen || warm_.load(std::memory_order_relaxed);
      });
      continue;
    }
    seen = now;
    if (stop_.load(std::memory_order_acquire)) return;
    const Job job = job_;
    t_pool = this;  // only while it works: its idle waits are not counted
    if (index < job.chunks) doChunk(job, index);
    t_pool = nullptr;
    remaining_.fetch_sub(1, std::memory_order_acq_rel);
  }
}

}  // namespace cairn
