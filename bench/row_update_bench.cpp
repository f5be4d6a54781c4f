// The cost of one PGS row update in the step's solver, contacts and joints
// apart, per instruction set (docs/performance.md records the figures).
//
//   BM_ContactRowUpdate/<kernels>   velocity sweeps over the contact
//       manifolds of pyramid-20 after 60 steps (the settled pile's graph,
//       captured from the World), one colour after another, as the step
//       sweeps them. rows = valid points x 3 (one normal and two friction
//       rows each); ns_per_row_update = time / (rows x sweeps).
//   BM_ContactSolve/<kernels>   the same rows solved as the step solves
//       them (solveGraph with the step's options: the warm start, then per
//       sweep the normal blocks, the friction rows and NNCG's momentum,
//       the passes interleaved where the step interleaves them);
//       ns_per_row_update = time / (rows x sweeps), the other passes'
//       time included. BM_ContactRowUpdate isolates the two row kernels,
//       colour after colour; this is what the step pays per row, and where
//       a change to a kernel must show to reach the step.
//   BM_JointRowUpdate   the same over the joint rows of chain-100 after 30
//       steps (mid-whip), each joint's rows in order.
//   BM_JointLanes/scene:S/lanes:L   the joints of many chains (S = 0) or
//       ragdolls (S = 1) side by side, solved in the kernels' lanes (L = 1)
//       or each alone (L = 0); its comment below has the scenes.
//
// The time is the thread's CPU time around the sweeps only (manual time):
// a loaded machine that deschedules the thread does not inflate it, but it
// still shares caches with whatever else runs, so compare figures taken in
// one run. Kernels the CPU lacks are skipped.
#include "solver/contact_kernels.hpp"
#include "solver/graph_solver.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <benchmark/benchmark.h>

#include <ctime>
#include <vector>

namespace cairn::bench {
namespace {

double threadSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Captured {
  GraphProblem graph;
  std::vector<SolverBody> velocities;
  int dynamic_end = 1;
  double contact_rows = 0, joint_rows = 0;
};

Captured capture(SceneDesc scene, int steps) {
  scene.solver.sleeping = false;
  // The graph holds the PGS islands only: auto's default would give
  // chain-100 to the direct solver and leave no joint rows to time.
  scene.solver.method = SolverMethod::PGS;
  World w = buildWorld(scene);
  for (int s = 0; s < steps; ++s) w.step(scene.dt);
  const detail::StepContext& ctx = detail::internals(w).stepContext();
  Captured c;
  c.graph = ctx.graph;
  c.velocities = ctx.velocities;
  c.dynamic_end = ctx.dynamic_count + 1;
  for (const ContactBatch& b : c.graph.batches)
    for (int l = 0; l < kBatchLanes; ++l)
      for (int i = 0; i < b.count[l]; ++i)
        if (b.p[i].valid[l] > 0) c.contact_rows += b.mu[l] > 0 ? 3 : 1;
  c.joint_rows = static_cast<double>(c.graph.rows.size());
  return c;
}

void BM_ContactRowUpdate(benchmark::State& state) {
  const auto level = static_cast<SimdLevel>(state.range(0));
  if (!simdLevelAvailable(level)) {
    state.SkipWithError("instruction set not available here");
    return;
  }
  static const Captured problem = capture(scenarios::byName("pyramid-20"), 60);
  if (problem.contact_rows == 0) {  // a figure over no rows would read as a time per row
    state.SkipWithError("pyramid-20 left no contact rows in the PGS graph");
    return;
  }
  const ContactKernels& k = contactKernels(level);
  state.SetLabel(k.name);
  constexpr int kSweeps = 10;
  GraphProblem g = problem.graph;
  std::vector<double> active(static_cast<size_t>(g.island_count), 1.0);
  ContactSweepParams p;
  p.dynamic_end = problem.dynamic_end;
  p.island_active = active.data();
  double seconds = 0, updates = 0;
  for (auto _ : state) {
    std::vector<SolverBody> v = problem.velocities;  // not timed
    const double t0 = threadSeconds();
    for (int s = 0; s < kSweeps; ++s) {  // a sweep as the step makes it: every normal block, then every friction row
      for (const GraphColour& c : g.colours)
        k.solve_normals(g.batches.data(), c.batch_begin, c.batch_end, v.front().v.data(), p);
      for (const GraphColour& c : g.colours)
        k.solve_friction(g.batches.data(), c.batch_begin, c.batch_end, v.front().v.data(), p);
    }
    benchmark::DoNotOptimize(v.data());
    benchmark::ClobberMemory();
    const double dt = threadSeconds() - t0;
    state.SetIterationTime(dt);
    seconds += dt;
    updates += problem.contact_rows * kSweeps;
  }
  state.counters["rows"] = problem.contact_rows;
  state.counters["colours"] = static_cast<double>(g.colours.size());
  state.counters["batches"] = static_cast<double>(g.batches.size());
  state.counters["ns_per_row_update"] = updates > 0 ? 1e9 * seconds / updates : 0;
}
BENCHMARK(BM_ContactRowUpdate)
    ->ArgName("simd")
    ->DenseRange(0, 2)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// Times solveGraph over `g` with options `o`: `prepare(g)` (not timed)
// sets its starting impulses before each run, and the figure is per row
// update over `rows` rows and the sweeps each run made.
template <class Prepare>
void timeSolveGraph(benchmark::State& state, GraphProblem& g, const std::vector<SolverBody>& velocities, double rows,
                    const GraphSolveOptions& o, Prepare&& prepare) {
  double seconds = 0, updates = 0;
  std::uint64_t rng = 1;
  for (auto _ : state) {
    std::vector<SolverBody> v = velocities;  // not timed
    prepare(g);
    const double t0 = threadSeconds();
    const GraphSolveStats st = solveGraph(g, v, o, rng);
    benchmark::DoNotOptimize(v.data());
    benchmark::ClobberMemory();
    const double dt = threadSeconds() - t0;
    state.SetIterationTime(dt);
    seconds += dt;
    updates += rows * st.iterations;
  }
  state.counters["rows"] = rows;
  state.counters["ns_per_row_update"] = updates > 0 ? 1e9 * seconds / updates : 0;
}

void BM_ContactSolve(benchmark::State& state) {
  const auto level = static_cast<SimdLevel>(state.range(0));
  if (!simdLevelAvailable(level)) {
    state.SkipWithError("instruction set not available here");
    return;
  }
  static const Captured problem = capture(scenarios::byName("pyramid-20"), 60);
  if (problem.contact_rows == 0) {
    state.SkipWithError("pyramid-20 left no contact rows in the PGS graph");
    return;
  }
  const ContactKernels& k = contactKernels(level);
  state.SetLabel(k.name);
  GraphSolveOptions o;  // the step's defaults (SolverSettings): 10 sweeps, NNCG, two tangent rows
  o.dynamic_end = problem.dynamic_end;
  o.kernels = &k;
  GraphProblem g;
  // Every run starts from the captured impulses.
  timeSolveGraph(state, g, problem.velocities, problem.contact_rows, o, [&](GraphProblem& p) { p = problem.graph; });
}
BENCHMARK(BM_ContactSolve)->ArgName("simd")->DenseRange(0, 2)->UseManualTime()->Unit(benchmark::kMicrosecond);

// Ten velocity sweeps without NNCG over a captured joint problem, cold
// (every sweep works), per row update over `rows`; the joints of a colour
// side by side in the kernels' lanes or each alone.
void timeColdSweeps(benchmark::State& state, const Captured& problem, double rows, bool joint_lanes) {
  GraphSolveOptions o;
  o.iterations = 10;
  o.nncg = false;
  o.dynamic_end = problem.dynamic_end;
  o.kernels = &contactKernels(bestSimdLevel());
  o.joint_lanes = joint_lanes;
  state.SetLabel(o.kernels->name);
  GraphProblem g;
  timeSolveGraph(state, g, problem.velocities, rows, o, [&](GraphProblem& p) {
    p = problem.graph;
    for (ConstraintRow& r : p.rows) r.lambda = 0;
  });
  state.counters["colours"] = static_cast<double>(g.colours.size());
  state.counters["lanes"] = static_cast<double>(g.joint_lanes.size());
}

void BM_JointRowUpdate(benchmark::State& state) {
  static const Captured problem = capture(scenarios::byName("chain-100"), 30);
  if (problem.joint_rows == 0) {
    state.SkipWithError("chain-100 left no joint rows in the PGS graph");
    return;
  }
  timeColdSweeps(state, problem, problem.joint_rows, true);
}
BENCHMARK(BM_JointRowUpdate)->UseManualTime()->Unit(benchmark::kMicrosecond);

// Joints side by side (solver/joint_lanes.hpp): the velocity sweeps, as
// BM_JointRowUpdate, over scenes whose colours hold many joints, with the
// joints of a colour in the kernels' lanes (lanes:1) or each alone
// (lanes:0), the same bits either way (tested):
//   scene:0  32 chains of 20 ball-jointed links side by side, after 30 steps
//            (every colour 32 ball joints of three rows);
//   scene:1  16 ragdolls side by side on the ground, after 60 steps (hinges
//            and cone-twists with their limits: colours of mixed row
//            counts, contacts beside them).
void BM_JointLanes(benchmark::State& state) {
  static const Captured chains = capture(scenarios::sideBySide(scenarios::chain(20), 32, Vec3(0, 0, 0.5)), 30);
  static const Captured ragdolls = capture(scenarios::sideBySide(scenarios::byName("ragdoll"), 16, Vec3(2.5, 0, 0)), 60);
  const Captured& problem = state.range(0) == 0 ? chains : ragdolls;
  timeColdSweeps(state, problem, problem.joint_rows + problem.contact_rows, state.range(1) != 0);
  state.counters["joint_rows"] = problem.joint_rows;
}
BENCHMARK(BM_JointLanes)
    ->ArgNames({"scene", "lanes"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cairn::bench
