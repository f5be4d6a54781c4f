// Sleeping islands must cost less than awake ones (docs/reliability.md,
// "Bounded resources"): 10,000 boxes resting on the ground (a 100 x 100
// grid, 1.5 m apart, so each is its own island), timed per World::step once
// settled, with sleeping off (every box awake, solved every step) and on
// (every box asleep after sleep_time).
//
//   ./build/bench/cairn_bench --benchmark_filter=RestingBoxes
//
// And what a step costs once a pile has gone to sleep: pile-1000 dropped
// into a heap and stepped until every box sleeps (300 steps; it sleeps at
// step 162), then one World::step of the sleeping heap, its contacts kept
// as they are (docs/performance.md).
//
//   ./build/bench/cairn_bench --benchmark_filter=AsleepPile
#include "validation/scenarios.hpp"

#include "cairn/scene.hpp"
#include "cairn/world.hpp"

#include <benchmark/benchmark.h>

namespace cairn::bench {
namespace {

void BM_RestingBoxes(benchmark::State& state) {
  const bool sleeping = state.range(0) != 0;
  SolverSettings s;
  s.sleeping = sleeping;
  World w(WorldDef{Vec3(0, Real(-9.81), 0), s});
  w.createBody(scenarios::ground());
  for (int i = 0; i < 100; ++i)
    for (int k = 0; k < 100; ++k) {
      BodyDef b;
      b.name = "box_" + std::to_string(i) + "_" + std::to_string(k);
      b.mass = 1;
      b.position = Vec3(Real(1.5) * (i - 50), Real(0.5), Real(1.5) * (k - 50));
      b.shapes.push_back(ShapeDesc::box(Vec3::Constant(0.5)));
      w.createBody(b);
    }
  const Real dt = Real(1) / 60;
  for (int i = 0; i < 60; ++i) w.step(dt);  // settled; asleep after sleep_time = 0.5 s when sleeping
  for (auto _ : state) w.step(dt);
  state.counters["sleeping_bodies"] = w.lastStepStats().sleeping_bodies;
  state.counters["contacts"] = w.lastStepStats().contacts;
}
BENCHMARK(BM_RestingBoxes)->ArgName("sleeping")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_AsleepPile1000(benchmark::State& state) {
  SceneDesc scene = scenarios::pile(10);
  scene.solver.sleeping = true;
  World w = buildWorld(scene);
  for (int i = 0; i < 300; ++i) w.step(scene.dt);
  for (auto _ : state) w.step(scene.dt);
  state.counters["sleeping_bodies"] = w.lastStepStats().sleeping_bodies;
  state.counters["contacts"] = w.lastStepStats().contacts;
}
BENCHMARK(BM_AsleepPile1000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cairn::bench
