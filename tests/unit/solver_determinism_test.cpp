// Same input, same output: the step's results do not depend on the number
// of worker threads nor on the instruction set the contact kernels use.
//
// Threads: the narrowphase's pairs and the contact batches' filling are
// independent, and the threads' contact lists are joined in pair order; a
// graph colour's constraints share no dynamic body, so solving
// them in any order or on any thread gives the same numbers; every sum
// (NNCG's norms) runs in storage order on one thread, and the sweeps'
// largest changes are maxima, whose value does not depend on the order. SIMD: the kernels are one template compiled per instruction
// set with -ffp-contract=off, so each lane performs the same IEEE operations
// in the same order as the portable path. Either way the trajectories must
// be equal bit for bit (==), not within a tolerance.
#include "solver/contact_kernels.hpp"
#include "solver/graph_solver.hpp"
#include "solver/worker_pool.hpp"
#include "test_helpers.hpp"
#include "validation/scenarios.hpp"
#include "validation/standard_scenes.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/pool_watch.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace cairn {
namespace {

struct Pose {
  Vec3 x, v, w;
  Quat q;
};

// A World on `threads` threads that keeps them for every step: it does not
// set its pool aside when the machine is busy (ctest runs two suites at
// once on these 2-core machines, and four threads oversubscribe it), so
// every step is a test of the threaded paths.
World threadedWorld(SceneDesc s, int threads) {
  s.solver.threads = threads;
  World w = buildWorld(s);
  detail::internals(w).pool_rules_ = PoolRules::None;
  return w;
}

std::vector<Pose> posesOf(World& w) {
  std::vector<Pose> out;
  for (const Body& b : detail::internals(w).bodies())
    out.push_back({b.position, b.linear_velocity, b.angular_velocity, b.orientation});
  return out;
}

std::vector<Pose> run(SceneDesc s, int steps, int threads, Simd simd) {
  s.solver.simd = simd;
  World w = threadedWorld(s, threads);
  for (int k = 0; k < steps; ++k) w.step(s.dt);
  return posesOf(w);
}

void expectIdentical(const std::vector<Pose>& a, const std::vector<Pose>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x) << "body " << i;
    EXPECT_EQ(a[i].v, b[i].v) << "body " << i;
    EXPECT_EQ(a[i].w, b[i].w) << "body " << i;
    EXPECT_EQ(a[i].q.coeffs(), b[i].q.coeffs()) << "body " << i;
  }
}

// A World whose two threads share one core with another busy task (as on
// a machine busy with other work) steps slower on them than on one: every
// handover between its threads waits for a thread that is not running. It
// sets its pool aside for a while after such a step (world/pool_watch.hpp;
// the rule's own tests: tests/unit/pool_watch_test.cpp). Whether a step
// is found sharing is the scheduler's doing, not asserted; what is: the
// steps alone come in the rule's runs, and since results do not depend on
// the thread count, the trajectory is one thread's, bit for bit.
TEST(Determinism, AWorldWhoseThreadsShareOneCoreStepsAloneWithTheSameBits) {
  const SceneDesc s = scenarios::pyramid(20);  // its passes side by side, its batches filled on the pool
  constexpr int kSharedSteps = 60;
  std::vector<int> threads;
  std::vector<Pose> shared;
  {
    const test::OneCore pinned;
    const test::BusyCore busy;  // another process on that core
    SceneDesc two = s;
    two.solver.threads = 2;
    World w = buildWorld(two);
    // Only the lost cores' rule, which the replay below follows: steps the
    // scheduler leaves clear would otherwise be timed against steps alone
    // on the shared core, and the pool set aside for no gain (that rule's
    // own tests: PoolWatch.*).
    detail::internals(w).pool_rules_ = PoolRules::LostCores;
    for (int k = 0; k < kSharedSteps; ++k) {
      w.step(s.dt);
      threads.push_back(w.lastStepStats().threads);
    }
    shared = posesOf(w);
  }
  // The rule replayed: a step on the pool followed by a step alone was
  // found sharing, one followed by another on the pool was not.
  PoolWatch replay;
  for (size_t k = 0; k < threads.size(); ++k) {
    const bool on_pool = replay.startStep();
    ASSERT_EQ(threads[k], on_pool ? 2 : 1) << "step " << k + 1 << " of " << ::testing::PrintToString(threads);
    if (on_pool) replay.endPoolStep(k + 1 < threads.size() && threads[k + 1] == 1 ? PoolWatch::kPreemptedPerStep : 0);
  }
  expectIdentical(run(s, kSharedSteps, 1, Simd::Auto), shared);
}

// The same with the lost cores simulated (WorkerPool::simulateLostCores:
// every step on the pool is found sharing), so the World follows the rule
// on every step whatever the scheduler does: steps 1, 18 and 51 on the
// pool (runs alone of 16 and 32), the rest alone, and one thread's bits.
TEST(Determinism, AWorldWhoseCoresAreLostStepsAloneByTheRuleWithTheSameBits) {
  const SceneDesc s = scenarios::pyramid(20);
  constexpr int kSteps = 60;
  SceneDesc two = s;
  two.solver.threads = 2;
  World w = buildWorld(two);
  std::vector<int> on_pool;
  WorkerPool::simulateLostCores(true);
  for (int k = 0; k < kSteps; ++k) {
    w.step(s.dt);
    if (w.lastStepStats().threads == 2) on_pool.push_back(k + 1);
  }
  WorkerPool::simulateLostCores(false);
  EXPECT_EQ(on_pool, (std::vector<int>{1, 18, 51}));
  expectIdentical(run(s, kSteps, 1, Simd::Auto), posesOf(w));
}

// 40 steps: the pyramid settles through its first contacts, the chain
// takes up its tension, the ragdoll falls (2 threads on these 2-core CI
// machines, 4 oversubscribed: the answer may not depend on either).
constexpr int kSteps = 40;
TEST(Determinism, PyramidIsBitIdenticalOnOneTwoAndFourThreads) {
  const SceneDesc s = scenarios::pyramid(10);
  const auto one = run(s, kSteps, 1, Simd::Auto);
  expectIdentical(one, run(s, kSteps, 2, Simd::Auto));
  expectIdentical(one, run(s, kSteps, 4, Simd::Auto));
}

TEST(Determinism, ChainAndRagdollAreBitIdenticalOnOneTwoAndFourThreads) {
  for (const SceneDesc& s : {scenarios::chain(20), scenarios::ragdoll()}) {
    const auto one = run(s, kSteps, 1, Simd::Auto);
    expectIdentical(one, run(s, kSteps, 2, Simd::Auto));
    expectIdentical(one, run(s, kSteps, 4, Simd::Auto));
  }
}

// 125 boxes dropped into a heap: fresh pairs every step through the
// narrowphase and new manifolds into the batches (a resting pyramid mostly
// recycles); the solve's colours are split among the threads.
TEST(Determinism, FallingPileIsBitIdenticalOnOneTwoAndFourThreads) {
  const SceneDesc s = scenarios::pile(5);
  const auto one = run(s, 60, 1, Simd::Auto);
  expectIdentical(one, run(s, 60, 2, Simd::Auto));
  expectIdentical(one, run(s, 60, 4, Simd::Auto));
}

// A heap of 216 boxes lands as 36 columns, 36 islands: with a pool the
// islands are split into one part per thread, each part swept to the end
// by its own thread (solver/graph_solver.hpp). The test checks that the
// parts were made, on two threads and on four, and that the trajectories
// equal those of one thread, where there are no parts.
TEST(Determinism, IslandsSweptAsOnePartPerThreadAreBitIdentical) {
  const SceneDesc s = scenarios::pile(6);
  constexpr int kPileSteps = 70;
  for (const int threads : {2, 4}) {
    World w = threadedWorld(s, threads);
    int parted = 0;
    for (int k = 0; k < kPileSteps; ++k) {
      w.step(s.dt);
      const GraphProblem& g = detail::internals(w).stepContext().graph;
      if (g.part_colour.size() == static_cast<size_t>(threads) + 1) ++parted;
    }
    EXPECT_GT(parted, 10) << threads << " threads";
  }
  const auto one = run(s, kPileSteps, 1, Simd::Auto);
  expectIdentical(one, run(s, kPileSteps, 2, Simd::Auto));
  expectIdentical(one, run(s, kPileSteps, 4, Simd::Auto));
}

// The scenes above stay below the thresholds past which collide, the
// broadphase's queries, the proxies' refit, the integration, the batch
// fill, the impulse store and the watchers hand their loops to the pool
// (world/parallel_thresholds.hpp). A pyramid of base 60 (1,830 boxes,
// about 5,400 touching manifolds) is past all of them from its first step
// (every proxy is new then, so every one is queried),
// and is one island, large enough that its colours are swept by the flow
// schedule (solver/colour_flow.hpp: each thread its share of every colour,
// waiting only for the other threads' items that touched its bodies last);
// the test checks all of that, on two threads and on four, before it
// compares 10 steps on 1, 2 and 4 threads.
TEST(Determinism, LargePyramidTakesEveryThreadedPathAndIsBitIdentical) {
  const SceneDesc s = scenarios::pyramid(60);
  for (const int threads : {2, 4}) {
    World w = threadedWorld(s, threads);
    w.step(s.dt);
    const detail::WorldImpl& in = detail::internals(w);
    const GraphProblem& g = in.stepContext().graph;
    const auto batches = static_cast<int>(g.batches.size());
    ASSERT_GE(static_cast<int>(in.pairs_.size()), detail::kParallelPairs);
    ASSERT_GE(static_cast<int>(in.shapes_.size()), detail::kParallelProxies);
    ASSERT_GE(static_cast<int>(in.shapes_.size()), detail::kParallelMovedProxies);
    ASSERT_GE(static_cast<int>(in.bodies().size()), detail::kParallelBodies);
    ASSERT_GE(batches, detail::kParallelBatches);
    ASSERT_GE(batches * kBatchLanes, detail::kParallelLanes);
    ASSERT_GE(static_cast<int>(in.contacts().size()), detail::kParallelContacts);
    // One island: no even split into parts; its colours are what the
    // threads share, by the flow schedule.
    ASSERT_TRUE(g.part_colour.empty());
    ASSERT_TRUE(g.flow.ready()) << threads << " threads";
  }
  const auto one = run(s, 10, 1, Simd::Auto);
  expectIdentical(one, run(s, 10, 2, Simd::Auto));
  expectIdentical(one, run(s, 10, 4, Simd::Auto));
}

// The contact events of a large scene are found on the pool's threads,
// each thread's kept apart and joined in range order
// (world/world_contacts.cpp, emitContactEvents): the same events in the
// same order, to the bit, on 1, 2 and 4 threads. The pyramid of base 60
// over 40 steps has thousands of Begin events and some End events (its
// upper boxes shift), so both halves are compared.
TEST(Determinism, ContactEventsAreTheSameOnAnyThreads) {
  const SceneDesc s = scenarios::pyramid(60);
  const auto events = [&](int threads) {
    World w = threadedWorld(s, threads);
    std::vector<ContactEvent> out;
    for (int k = 0; k < 40; ++k) {
      w.step(s.dt);
      const auto& step = detail::internals(w).contactEvents();
      out.insert(out.end(), step.begin(), step.end());
    }
    return out;
  };
  const std::vector<ContactEvent> one = events(1);
  const auto ends = std::count_if(one.begin(), one.end(), [](const ContactEvent& e) { return e.type == ContactEvent::Type::End; });
  ASSERT_GT(static_cast<int>(one.size()) - ends, detail::kParallelContacts);
  ASSERT_GT(ends, 0);
  for (const int threads : {2, 4}) {
    const std::vector<ContactEvent> many = events(threads);
    ASSERT_EQ(one.size(), many.size()) << threads << " threads";
    for (size_t i = 0; i < one.size(); ++i) {
      const ContactEvent &a = one[i], &b = many[i];
      EXPECT_TRUE(a.type == b.type && a.step == b.step && a.body_a == b.body_a && a.body_b == b.body_b &&
                  a.shape_a == b.shape_a && a.shape_b == b.shape_b && a.point == b.point && a.normal == b.normal &&
                  a.impulse == b.impulse)
          << "event " << i << ", " << threads << " threads";
    }
  }
}

// A graph whose constraints are those of the step before keeps its layout
// (world/step_prepare.cpp, layoutGraph), and with it the flow schedule or
// the pipeline planned on it where it has no row groups. Kept, it must
// give the bits of a layout made afresh at every step: a resting pyramid
// of base 40 (one island, the flow schedule on two threads, the pipeline
// on one), which keeps its layout for most of its first 60 steps; a hinge
// chain swept by PGS (row groups: the plans are made again), which keeps
// it for all but its first; and a pyramid of base 10 whose pre-solve
// callback vetoes a different one of its contacts each step, whose graph
// then has as many constraints every step but not the same ones, and must
// be laid out every step. On one and two threads.
TEST(Determinism, AKeptLayoutGivesTheBitsOfOneMadeAfresh) {
  SceneDesc chain = validation::standardScene("hinge-chain").scene;
  chain.solver.method = SolverMethod::PGS;
  struct Case {
    const char* name;
    SceneDesc scene;
    int steps;
    bool veto;       // a different contact vetoed each step
    int most_made;   // the most layouts made in the kept world
  };
  for (const Case& c : {Case{"pyramid-40", scenarios::pyramid(40), 60, false, 30},
                        Case{"hinge-chain", chain, 120, false, 1}, Case{"pyramid-10", scenarios::pyramid(10), 40, true, 40}})
    for (const int threads : {1, 2}) {
      World kept = threadedWorld(c.scene, threads), fresh = threadedWorld(c.scene, threads);
      int step = 0, seen = 0;
      const auto veto = [&](ContactInfo& info) {
        if (seen++ % 7 == step % 7) info.enabled = false;
      };
      if (c.veto) {
        kept.setPreSolveCallback(veto);
        fresh.setPreSolveCallback(veto);
      }
      for (; step < c.steps; ++step) {
        detail::internals(fresh).ctx_.graph.laid_out = false;
        seen = 0;
        kept.step(c.scene.dt);
        seen = 0;
        fresh.step(c.scene.dt);
      }
      expectIdentical(posesOf(kept), posesOf(fresh));
      const std::int64_t made = detail::internals(kept).stepContext().layout_inputs.made;
      EXPECT_EQ(detail::internals(fresh).stepContext().layout_inputs.made, c.steps);
      EXPECT_LE(made, c.most_made) << c.name << ", " << threads << " threads";
      EXPECT_GE(made, 1);
      if (c.veto) {
        EXPECT_EQ(made, c.steps) << c.name << ", " << threads << " threads";
      }
    }
}

// A pyramid of base 30 (465 boxes, about 220 batches) is one island too
// small for the flow schedule (solver/graph_solver.cpp, kFlowWork) and
// large enough (kPipelineBatches) that the passes of a sweep run side by
// side: the friction pass on one thread a few constraints behind the
// normal pass on the other (solver/pass_pipeline.hpp). Its lowest colours
// hold the four batches or more past which a colour of a single pass (the
// correction passes, restitution) is split among the threads at a barrier
// (kParallelWork); with randomize_order the sweeps take that path too. The
// test checks the paths were taken, on two threads and on four, then
// compares 20 steps on 1, 2 and 4 threads, in colour order and shuffled
// (OverlappedPassesGiveTheBitsOfPassAfterPass checks each overlap against
// pass after pass).
TEST(Determinism, MidSizedPyramidRunsItsPassesSideBySideAndIsBitIdentical) {
  const SceneDesc s = scenarios::pyramid(30);
  constexpr int kSplitColour = 4;  // graph_solver.cpp, kParallelWork
  for (const int threads : {2, 4}) {
    World w = threadedWorld(s, threads);
    w.step(s.dt);
    const GraphProblem& g = detail::internals(w).stepContext().graph;
    ASSERT_TRUE(g.part_colour.empty());
    ASSERT_FALSE(g.flow.ready()) << threads << " threads";
    ASSERT_TRUE(g.pipeline.planned()) << threads << " threads";
    int widest = 0;
    for (const GraphColour& c : g.colours) widest = std::max(widest, c.batch_end - c.batch_begin);
    ASSERT_GE(widest, kSplitColour);
  }
  SceneDesc shuffled = s;
  shuffled.solver.randomize_order = true;
  for (const SceneDesc& scene : {s, shuffled}) {
    const auto one = run(scene, 20, 1, Simd::Auto);
    expectIdentical(one, run(scene, 20, 2, Simd::Auto));
    expectIdentical(one, run(scene, 20, 4, Simd::Auto));
  }
}

// Two copies of the graph the step left in `w`, and of its velocities, to
// solve two ways from the same state, with the step's options (on `pool`).
// Their plans (pass pipeline, flow schedule) are reset, so that each solve
// makes its own.
struct TwoSolves {
  GraphSolveOptions options;
  GraphProblem graph[2];
  std::vector<SolverBody> velocities[2];
  TwoSolves(const World& w, WorkerPool* pool) {
    const detail::StepContext& ctx = detail::internals(w).stepContext();
    options.dynamic_end = ctx.dynamic_count + 1;
    options.kernels = &contactKernels(bestSimdLevel());
    options.pool = pool;
    for (int k = 0; k < 2; ++k) {
      graph[k] = ctx.graph;
      graph[k].pipeline.reset();
      graph[k].flow.reset();
      velocities[k] = ctx.velocities;
    }
  }
};

// Solves the graph the step left in `w` twice from the same state, its
// passes overlapped and pass after pass, and compares the impulses and
// velocities with ==.
enum class Overlap { Interleaved, SideBySide, FlowInterleaved };
void expectOverlapGivesTheBitsOfPassAfterPass(const World& w, WorkerPool* pool, Overlap overlap) {
  for (const bool nncg : {true, false}) {
    TwoSolves two(w, pool);
    GraphSolveOptions& o = two.options;
    o.nncg = nncg;
    GraphProblem &overlapped = two.graph[0], &in_turn = two.graph[1];
    std::vector<SolverBody> &v_overlapped = two.velocities[0], &v_in_turn = two.velocities[1];
    std::uint64_t rng = 1;
    solveGraph(overlapped, v_overlapped, o, rng);
    o.overlap_passes = false;
    solveGraph(in_turn, v_in_turn, o, rng);
    ASSERT_EQ(overlapped.flow.ready(), overlap == Overlap::FlowInterleaved);
    ASSERT_EQ(overlapped.pipeline.planned(), overlap != Overlap::FlowInterleaved);
    ASSERT_FALSE(in_turn.pipeline.planned());
    for (size_t i = 0; i < v_in_turn.size(); ++i) {
      EXPECT_EQ(v_overlapped[i].v, v_in_turn[i].v) << "body " << i;
      EXPECT_EQ(v_overlapped[i].w, v_in_turn[i].w) << "body " << i;
    }
    int differ = 0;
    for (size_t b = 0; b < in_turn.batches.size(); ++b)
      for (int i = 0; i < kMaxPoints; ++i)
        for (int l = 0; l < kBatchLanes; ++l) {
          const ContactBatch::Point& p = overlapped.batches[b].p[i];
          const ContactBatch::Point& q = in_turn.batches[b].p[i];
          differ += p.lambda[l] != q.lambda[l] || p.lambda_t[0][l] != q.lambda_t[0][l] ||
                    p.lambda_t[1][l] != q.lambda_t[1][l];
        }
    EXPECT_EQ(differ, 0) << (nncg ? "NNCG" : "PGS");
  }
}

// Where planned, the passes of a sweep overlap (solver/pass_pipeline.hpp):
// interleaved on one thread, side by side on a pool, and interleaved by
// each thread of the flow schedule (solver/colour_flow.hpp) on a large
// island. Each reorders only constraints that share no body, so the
// impulses and velocities must be those of pass after pass, bit for bit,
// with NNCG's momentum pass and without it. The problems are pyramids' as
// the step left them (warm impulses, the bodies' velocities): base 30 is
// past the pipeline's size, base 60 past the flow schedule's.
TEST(Determinism, OverlappedPassesGiveTheBitsOfPassAfterPass) {
  World mid = buildWorld(scenarios::pyramid(30));
  World large = buildWorld(scenarios::pyramid(60));
  for (int k = 0; k < 3; ++k) {
    mid.step(1.0 / 60);
    large.step(1.0 / 60);
  }
  WorkerPool pool(2);
  expectOverlapGivesTheBitsOfPassAfterPass(mid, nullptr, Overlap::Interleaved);
  expectOverlapGivesTheBitsOfPassAfterPass(mid, &pool, Overlap::SideBySide);
  expectOverlapGivesTheBitsOfPassAfterPass(large, &pool, Overlap::FlowInterleaved);
}

// A pyramid whose rows sink 3 cm into each other and the bottom row 3 cm
// into the ground (past the 5 mm slop), so that every contact has a
// split-impulse correction target at the first step.
SceneDesc sunkenPyramid(int n) {
  SceneDesc s = scenarios::pyramid(n);
  for (BodyDef& b : s.bodies)
    if (b.mass > 0) b.position.y() -= Real(0.03) * (b.position.y() + Real(0.5));
  return s;
}

// Solves the graph of the first step of `s` (on `pool`) twice from the
// same state: its split-impulse correction swept with the velocities, and
// in a pass of its own after them; compares the pseudo-velocities, the
// correction impulses and the velocities with ==. `tolerance` lets the
// velocity sweeps stop before the correction's, so that the correction
// also sweeps alone after them (asserted).
void expectSweptCorrectionGivesTheBitsOfItsOwnPass(const SceneDesc& s, WorkerPool* pool, Real tolerance) {
  World w = buildWorld(s);
  w.step(s.dt);
  TwoSolves two(w, pool);
  GraphSolveOptions& o = two.options;
  o.tolerance = tolerance;
  GraphProblem &swept = two.graph[0], &own = two.graph[1];
  std::vector<SolverBody> &v_swept = two.velocities[0], &v_own = two.velocities[1];
  std::vector<SolverBody> p_swept(v_own.size()), p_own(v_own.size());
  std::uint64_t rng = 1;
  solveGraph(swept, v_swept, o, rng, p_swept);
  EXPECT_TRUE(solveGraphCorrection(swept, v_swept, p_swept, o));
  o.sweep_correction = false;
  const GraphSolveStats velocity = solveGraph(own, v_own, o, rng, p_own);
  EXPECT_TRUE(solveGraphCorrection(own, v_own, p_own, o));
  ASSERT_TRUE(swept.correction_swept);
  ASSERT_FALSE(own.correction_swept);
  if (tolerance > 0) {  // the correction's own pass swept longer than the velocities
    const int correction = *std::max_element(own.island_iterations.begin(), own.island_iterations.end());
    ASSERT_GT(correction, velocity.iterations);
  }
  for (size_t i = 0; i < v_own.size(); ++i) {
    EXPECT_EQ(p_swept[i].v, p_own[i].v) << "body " << i;
    EXPECT_EQ(p_swept[i].w, p_own[i].w) << "body " << i;
    EXPECT_EQ(v_swept[i].v, v_own[i].v) << "body " << i;
    EXPECT_EQ(v_swept[i].w, v_own[i].w) << "body " << i;
  }
  int differ = 0, pushing = 0;
  for (size_t b = 0; b < own.batches.size(); ++b)
    for (int i = 0; i < kMaxPoints; ++i)
      for (int l = 0; l < kBatchLanes; ++l) {
        differ += swept.batches[b].p[i].lambda_bias[l] != own.batches[b].p[i].lambda_bias[l];
        pushing += own.batches[b].p[i].lambda_bias[l] > 0;
      }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(pushing, 0);
}

// The contacts' split-impulse correction is swept with the velocities,
// each of its block visits in the normal visit of the same batch
// (GraphSolveOptions::sweep_correction). It reads nothing the velocity
// sweeps write and keeps its colour order and its own stopping test, so
// its pseudo-velocities must be those of its own pass, bit for bit: on one
// thread (interleaved passes, base 30), side by side on two (base 30),
// by the flow schedule (base 60), and where it sweeps on alone after the
// velocity sweeps stop (a tolerance).
TEST(Determinism, CorrectionSweptWithTheVelocitiesGivesTheBitsOfItsOwnPass) {
  WorkerPool pool(2);
  expectSweptCorrectionGivesTheBitsOfItsOwnPass(sunkenPyramid(30), nullptr, 0);
  expectSweptCorrectionGivesTheBitsOfItsOwnPass(sunkenPyramid(30), &pool, 0);
  expectSweptCorrectionGivesTheBitsOfItsOwnPass(sunkenPyramid(60), &pool, 0);
  // 1 cm/s: the velocity sweeps stop after 4 of the 10 (base 30), the
  // correction's after 10.
  expectSweptCorrectionGivesTheBitsOfItsOwnPass(sunkenPyramid(30), nullptr, Real(1e-2));
  expectSweptCorrectionGivesTheBitsOfItsOwnPass(sunkenPyramid(60), &pool, Real(1e-2));
}

// Joints side by side (solver/joint_lanes.hpp): up to eight joints of a
// colour with the same number of rows are solved at once, one per vector
// lane, with the arithmetic of each joint's own visit, so the impulses and
// velocities must be those of every joint solved alone, bit for bit: with
// every instruction set's kernels, on one thread and on two (a colour's
// joints split between the threads), with NNCG's momentum (its steps in
// the lanes too) and without, with the position-correction passes after
// the sweeps, and with a tolerance at which the islands
// stop after different numbers of sweeps (lanes of a stopped island left
// as they are). Scenes: 32 chains of 20 ball joints, each nudged sideways
// at its own speed, 0.25 m/s more than the last (every colour 32 joints
// of three rows; the islands converge at different rates), and 16 ragdolls on
// the ground (hinges and cone-twists with their limits: colours of mixed
// row counts, contacts beside them).
SceneDesc nudgedChains() {
  SceneDesc s = scenarios::sideBySide(scenarios::chain(20), 32, Vec3(0, 0, 0.5));
  for (size_t i = 0; i < s.bodies.size(); ++i) s.bodies[i].linear_velocity = Vec3(0, 0, Real(0.25) * Real(i / 20));
  s.solver.method = SolverMethod::PGS;
  return s;
}

void expectLanesGiveTheBitsOfJointsAlone(const World& w, WorkerPool* pool, SimdLevel level, bool nncg,
                                         Real tolerance) {
  TwoSolves two(w, pool);
  GraphSolveOptions& o = two.options;
  o.kernels = &contactKernels(level);
  o.nncg = nncg;
  o.tolerance = tolerance;
  GraphProblem &lanes = two.graph[0], &alone = two.graph[1];
  std::vector<SolverBody> pseudo[2] = {std::vector<SolverBody>(two.velocities[0].size()),
                                       std::vector<SolverBody>(two.velocities[0].size())};
  std::uint64_t rng = 1;
  solveGraph(lanes, two.velocities[0], o, rng, pseudo[0]);
  const bool corrected = solveGraphCorrection(lanes, two.velocities[0], pseudo[0], o);
  o.joint_lanes = false;
  solveGraph(alone, two.velocities[1], o, rng, pseudo[1]);
  const std::vector<int> sweeps = alone.island_iterations;
  EXPECT_EQ(solveGraphCorrection(alone, two.velocities[1], pseudo[1], o), corrected);
  ASSERT_FALSE(lanes.joint_lanes.empty());
  ASSERT_TRUE(alone.joint_lanes.empty());
  if (tolerance > 0) {
    const auto [fewest, most] = std::minmax_element(sweeps.begin(), sweeps.end());
    ASSERT_LT(*fewest, *most) << "every island swept as long: no lane of a stopped island";
  }
  // The joints' position error is corrected after the sweeps (its own
  // passes, visited in the lanes too): there must be some.
  ASSERT_TRUE(std::any_of(alone.rows.begin(), alone.rows.end(), [](const ConstraintRow& r) {
    return r.correction != Correction::InRhs && r.bias_rhs != 0;
  }));
  for (size_t i = 0; i < two.velocities[1].size(); ++i) {
    EXPECT_EQ(two.velocities[0][i].v, two.velocities[1][i].v) << "body " << i;
    EXPECT_EQ(two.velocities[0][i].w, two.velocities[1][i].w) << "body " << i;
    EXPECT_EQ(pseudo[0][i].v, pseudo[1][i].v) << "body " << i;
    EXPECT_EQ(pseudo[0][i].w, pseudo[1][i].w) << "body " << i;
  }
  int differ = 0;
  for (size_t r = 0; r < alone.rows.size(); ++r) differ += lanes.rows[r].lambda != alone.rows[r].lambda;
  EXPECT_EQ(differ, 0) << simdLevelName(level) << (nncg ? " NNCG" : " PGS") << " tolerance " << tolerance;
}

TEST(Determinism, JointsInLanesGiveTheBitsOfEachJointAlone) {
  WorkerPool pool(2);
  SceneDesc ragdolls = scenarios::sideBySide(scenarios::ragdoll(), 16, Vec3(2.5, 0, 0));
  ragdolls.solver.method = SolverMethod::PGS;
  const SceneDesc chains = nudgedChains();
  for (const auto& [s, steps] : {std::pair{chains, 30}, std::pair{ragdolls, 60}}) {
    World w = buildWorld(s);
    for (int k = 0; k < steps; ++k) w.step(s.dt);
    ASSERT_FALSE(detail::internals(w).stepContext().graph.joint_lanes.empty()) << "the step made no lanes";
    for (const SimdLevel level : {SimdLevel::Portable, SimdLevel::Avx2, SimdLevel::Avx512}) {
      if (!simdLevelAvailable(level)) continue;
      for (WorkerPool* p : {static_cast<WorkerPool*>(nullptr), &pool})
        for (const bool nncg : {true, false}) expectLanesGiveTheBitsOfJointsAlone(w, p, level, nncg, 0);
    }
  }
  World w = buildWorld(chains);
  for (int k = 0; k < 30; ++k) w.step(chains.dt);
  // 0.01 N s: the chains' islands stop after 1 to 10 sweeps.
  for (WorkerPool* p : {static_cast<WorkerPool*>(nullptr), &pool})
    expectLanesGiveTheBitsOfJointsAlone(w, p, bestSimdLevel(), true, Real(1e-2));
}

// Contacts over substeps, both ways (SolverSettings::
// prepare_contacts_each_substep): refreshed at later substeps (the
// default), pyramid-20's 111 batches are refreshed on the pool's threads
// and by each kernel level's refresh; prepared anew, they are filled
// again; either way with one set of bits.
TEST(Determinism, ContactsOverSubstepsAreBitIdenticalOnAnyThreadsAndKernels) {
  for (const bool prepare_each : {false, true}) {
    SCOPED_TRACE(prepare_each ? "prepared each substep" : "refreshed");
    SceneDesc s = scenarios::pyramid(20);
    s.solver.substeps = 4;
    s.solver.iterations = 3;
    s.solver.prepare_contacts_each_substep = prepare_each;
    const auto one = run(s, 20, 1, Simd::Portable);
    expectIdentical(one, run(s, 20, 2, Simd::Portable));
    if (simdLevelAvailable(SimdLevel::Avx2)) expectIdentical(one, run(s, 20, 2, Simd::Avx2));
    if (simdLevelAvailable(SimdLevel::Avx512)) expectIdentical(one, run(s, 20, 1, Simd::Avx512));
  }
}

// Friction per patch (SolverSettings::patch_friction): its 2 x 2 block, the
// disc, the twist row and its NNCG momentum go through the same lanes, so
// pyramid-20 gives one set of bits on any threads and kernels, at one
// substep and at four (where its twist impulse is carried by the refresh).
TEST(Determinism, PatchFrictionIsBitIdenticalOnAnyThreadsAndKernels) {
  for (const int substeps : {1, 4}) {
    SCOPED_TRACE(substeps);
    SceneDesc s = scenarios::pyramid(20);
    s.solver.patch_friction = true;
    s.solver.substeps = substeps;
    s.solver.iterations = substeps == 1 ? 10 : 3;
    const auto one = run(s, 20, 1, Simd::Portable);
    expectIdentical(one, run(s, 20, 2, Simd::Portable));
    if (simdLevelAvailable(SimdLevel::Avx2)) expectIdentical(one, run(s, 20, 2, Simd::Avx2));
    if (simdLevelAvailable(SimdLevel::Avx512)) expectIdentical(one, run(s, 20, 1, Simd::Avx512));
  }
}

TEST(Determinism, PortableAndSimdKernelsGiveIdenticalTrajectories) {
  const SceneDesc s = scenarios::pyramid(10);
  const auto portable = run(s, kSteps, 1, Simd::Portable);
  if (simdLevelAvailable(SimdLevel::Avx2)) expectIdentical(portable, run(s, kSteps, 1, Simd::Avx2));
  if (simdLevelAvailable(SimdLevel::Avx512)) expectIdentical(portable, run(s, kSteps, 1, Simd::Avx512));
}

}  // namespace
}  // namespace cairn
