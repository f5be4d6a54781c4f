// The step allocates nothing once warmed up: every scratch array lives in
// the step's context and keeps its capacity from step to step (as Box2D v3's
// stack allocator and Jolt's temp allocator do), so a steady scene costs no
// trips to the heap. Counted by replacing the global operator new in this
// test binary; the count is read only around the steps under test.
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <utility>

// Under AddressSanitizer the allocator is ASan's (it pairs every new with
// its delete, which a partial replacement here would break): the count is
// taken in the ordinary builds only, and the tests skip themselves there.
#if defined(__SANITIZE_ADDRESS__)
#define CAIRN_COUNT_ALLOCATIONS 0
#else
#define CAIRN_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<long> g_allocations{0};
}

#if CAIRN_COUNT_ALLOCATIONS
// The replacements pair malloc with free by construction; GCC, inlining
// them into a caller's new/delete, cannot see that and would warn.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#endif

namespace cairn {
namespace {

// Allocations made by `steps` steps after `warmup` steps of the scene;
// `check` sees the World after the last step (that it took the path the
// test is about).
template <class Check>
long allocationsAfterWarmUp(SceneDesc s, int warmup, int steps, Check&& check) {
  if (!CAIRN_COUNT_ALLOCATIONS) return 0;
  s.solver.sleeping = false;
  World w = buildWorld(s);
  for (int k = 0; k < warmup; ++k) w.step(s.dt);
  const long before = g_allocations.load();
  for (int k = 0; k < steps; ++k) w.step(s.dt);
  const long made = g_allocations.load() - before;
  check(w);
  return made;
}
long allocationsAfterWarmUp(SceneDesc s, int warmup, int steps) {
  return allocationsAfterWarmUp(std::move(s), warmup, steps, [](const World&) {});
}

// A resting pyramid keeps its contact set: after the first second every
// array has reached its size.
TEST(StepAllocations, RestingPyramidAllocatesNothingAfterWarmUp) {
  if (!CAIRN_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are ASan's in this build";
  EXPECT_EQ(allocationsAfterWarmUp(scenarios::pyramid(10), 60, 60), 0);
}

// Joint rows only: the chain's row groups are rebuilt in place each step.
// (A hanging chain: a chain that whips open under PGS is reported by a
// joint-drift diagnostic each step, whose message is a new string.)
TEST(StepAllocations, HangingChainAllocatesNothingAfterWarmUp) {
  if (!CAIRN_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are ASan's in this build";
  EXPECT_EQ(allocationsAfterWarmUp(scenarios::hangingChain(20), 60, 60), 0);
}

// A long chain goes to the direct solver (the tree factor), and its joint
// position pass runs Newton steps with rows built anew and displacements
// taken back (whose callbacks and scratch once allocated every substep).
TEST(StepAllocations, DirectChainWithItsPositionPassAllocatesNothingAfterWarmUp) {
  if (!CAIRN_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are ASan's in this build";
  EXPECT_EQ(allocationsAfterWarmUp(scenarios::chain(100), 60, 60,
                                   [](const World& w) {
                                     const StepStats& st = w.lastStepStats();
                                     EXPECT_EQ(st.islands_by_method[static_cast<int>(SolverMethod::Direct)], 1);
                                     EXPECT_GT(st.position_iterations, 0);
                                   }),
            0);
}

// A box 100 times heavier than the one it rests on goes to the exact LCP
// solver (Dantzig's pivoting, a Newton step on the friction coupling),
// whose dense problem, factor and vectors are kept from step to step.
TEST(StepAllocations, ExactMassRatioStackAllocatesNothingAfterWarmUp) {
  if (!CAIRN_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocations are ASan's in this build";
  EXPECT_EQ(allocationsAfterWarmUp(scenarios::massRatio(100), 60, 60,
                                   [](const World& w) {
                                     EXPECT_EQ(w.lastStepStats().islands_by_method[static_cast<int>(SolverMethod::LCP)], 1);
                                   }),
            0);
}

}  // namespace
}  // namespace cairn
