// The flow schedule's threads (solver/colour_flow.hpp) may run an item
// ahead of one before it on their thread that waits for the other thread.
// What must hold whatever the timing: every dynamic body sees its
// constraints in the order one thread gives them, pass by pass and colour
// by colour, each exactly once.
#include "solver/colour_flow.hpp"
#include "solver/graph_solver.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include "cairn/world.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <utility>
#include <vector>

namespace cairn {
namespace {

// The visits of one body: (pass, colour) in the order they ran.
using Visits = std::vector<std::pair<int, std::int32_t>>;

// Busy for `us` microseconds (a sleep would give the core away, and the
// point is a thread that is slow, not one that is gone).
void spinFor(int us) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::microseconds(us);
  while (std::chrono::steady_clock::now() < end) {
  }
}

// A pyramid of base 60 as the step left it: one island of 1,830 boxes,
// large enough for the flow schedule, planned for two and for four
// threads. Every thread but the first is slowed on every third item it
// runs, so the threads find their next items waiting for each other again
// and again, and run what comes after them.
TEST(ColourFlow, ItemsRunAheadOfAWaitingOneKeepEveryBodysOrder) {
  World w = buildWorld(scenarios::pyramid(60));
  for (int k = 0; k < 3; ++k) w.step(1.0 / 60);
  const detail::StepContext& ctx = detail::internals(w).stepContext();
  const int dynamic_end = ctx.dynamic_count + 1;

  // One thread's order: pass after pass, colour after colour.
  constexpr int kPasses = 3;
  const GraphProblem& step_graph = ctx.graph;
  std::vector<Visits> expected(static_cast<size_t>(dynamic_end));
  std::vector<std::int32_t> bodies;
  for (int j = 0; j < kPasses; ++j)
    for (std::int32_t c = 0; c < static_cast<std::int32_t>(step_graph.colours.size()); ++c) {
      const GraphColour& gc = step_graph.colours[static_cast<size_t>(c)];
      const std::int32_t items = gc.group_end - gc.group_begin + gc.batch_end - gc.batch_begin;
      for (std::int32_t i = 0; i < items; ++i) {
        bodies.clear();
        appendItemBodies(step_graph, {c, i}, dynamic_end, bodies);
        for (const std::int32_t b : bodies) expected[static_cast<size_t>(b)].emplace_back(j, c);
      }
    }

  for (const int threads : {2, 4}) {
    GraphProblem g = step_graph;
    g.flow.reset();
    ASSERT_TRUE(g.flow.plan(g, threads, dynamic_end, 0)) << threads << " threads";
    WorkerPool pool(threads);
    for (int round = 0; round < 3; ++round) {
      std::vector<Visits> got(static_cast<size_t>(dynamic_end));
      std::mutex log;
      std::vector<int> slow_count(static_cast<size_t>(threads));  // each thread its own
      g.flow.runInterleaved(pool, kPasses, [&](int j, const FlowItem& it) {
        const int t = WorkerPool::currentThread();
        if (t > 0 && ++slow_count[static_cast<size_t>(t)] % 3 == 0) spinFor(20);
        std::vector<std::int32_t> mine;
        appendItemBodies(g, it, dynamic_end, mine);
        const std::lock_guard<std::mutex> lock(log);
        for (const std::int32_t b : mine) got[static_cast<size_t>(b)].emplace_back(j, it.colour);
      });
      int differ = 0;
      for (size_t b = 0; b < expected.size(); ++b) differ += got[b] != expected[b];
      EXPECT_EQ(differ, 0) << threads << " threads, round " << round;
      // The look ahead was used: the test exercises what it is about.
      EXPECT_GT(g.flow.passedOver(), 0) << threads << " threads, round " << round;
    }
  }
}

}  // namespace
}  // namespace cairn
