// Solver and step timings (Google Benchmark). docs/benchmarks.md records
// the results and the command that produced them.
//
//   BM_PgsChain100   solvePgs alone over the rows of chain-100 (300 ball
//                    rows), captured from a World mid-whip: the counter
//                    ns_per_row_iter = time / (rows x sweeps) is the cost of
//                    one row update (dot product, clamp, two axpy's). The
//                    time is the thread's CPU time around solvePgs only
//                    (manual time), so a loaded machine that deschedules
//                    the thread does not inflate it.
//   BM_Step*         a whole World::step (rows, warm start, PGS, the
//                    position-correction pass, integration, feedback)
#include "bench/thread_clock.hpp"
#include "solver/pgs.hpp"
#include "validation/scenarios.hpp"
#include "world/world_access.hpp"

#include <benchmark/benchmark.h>

#include <vector>

namespace cairn::bench {
namespace {

struct PgsProblem {
  std::vector<ConstraintRow> rows;
  std::vector<SolverBody> bodies;
};

PgsProblem capture(const SceneDesc& scene, int warm_steps) {
  World w = buildWorld(scene);
  for (int s = 0; s < warm_steps; ++s) w.step(scene.dt);
  PgsProblem p;
  p.rows = cairn::detail::internals(w).expandedRows();
  p.bodies.resize(static_cast<size_t>(w.bodyCount()) + 1);
  for (int i = 0; i < w.bodyCount(); ++i) {
    const Body& b = cairn::detail::internals(w).bodies()[static_cast<size_t>(i)];
    const Vec3 dv = b.isDynamic() ? Vec3(scene.dt * w.gravity()) : Vec3::Zero();
    p.bodies[static_cast<size_t>(i) + 1] = SolverBody{b.linear_velocity + dv, b.angular_velocity};
  }
  return p;
}

void BM_PgsChain100(benchmark::State& state) {
  static const PgsProblem problem = [] {
    SceneDesc scene = scenarios::chain(100);
    scene.solver.sleeping = false;
    return capture(scene, 30);
  }();
  PgsSettings ps;
  ps.iterations = static_cast<int>(state.range(0));
  ps.randomize_order = state.range(1) != 0;
  std::vector<ConstraintRow> rows;
  std::vector<SolverBody> bodies;
  PgsScratch scratch;
  std::uint64_t rng = ps.seed;
  double seconds = 0, row_iterations = 0;
  for (auto _ : state) {
    rows = problem.rows;  // fresh copy each time, not timed
    bodies = problem.bodies;
    applyWarmStart(rows, bodies);
    const double t0 = threadSeconds();
    const PgsStats st = solvePgs(rows, bodies, ps, scratch, rng);
    benchmark::DoNotOptimize(bodies.data());
    benchmark::ClobberMemory();
    const double dt = threadSeconds() - t0;
    state.SetIterationTime(dt);
    seconds += dt;
    row_iterations += static_cast<double>(rows.size()) * st.iterations;
  }
  state.counters["rows"] = static_cast<double>(problem.rows.size());
  state.counters["ns_per_row_iter"] = row_iterations > 0 ? 1e9 * seconds / row_iterations : 0;
}
BENCHMARK(BM_PgsChain100)
    ->ArgNames({"iterations", "randomized"})
    ->ArgsProduct({{10, 100}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// World::step on a standard scenario, after `warm_steps` steps so the
// warm-start impulses and the motion are those of a running simulation.
void stepScenario(benchmark::State& state, const char* name, int warm_steps) {
  SceneDesc scene = scenarios::byName(name);
  scene.solver.sleeping = false;
  World w = buildWorld(scene);
  for (int s = 0; s < warm_steps; ++s) w.step(scene.dt);
  for (auto _ : state) w.step(scene.dt);
  if (!w.numericalEvents().empty()) state.SkipWithError("non-finite state during the benchmark");
  state.counters["rows"] = w.lastStepStats().rows;
  state.counters["bodies"] = w.bodyCount();
}

void BM_StepChain100(benchmark::State& state) { stepScenario(state, "chain-100", 30); }
BENCHMARK(BM_StepChain100)->Unit(benchmark::kMicrosecond);

void BM_StepHingePendulum(benchmark::State& state) { stepScenario(state, "hinge-pendulum-1.5", 30); }
BENCHMARK(BM_StepHingePendulum)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cairn::bench
