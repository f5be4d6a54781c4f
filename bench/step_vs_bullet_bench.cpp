// cairn and Bullet 3.24 (double precision) stepping the same standard scene
// with matched settings (validation/bullet_oracle.hpp, match_cairn), in the
// same process, one after the other: compare the two rows of a scene, not
// absolute times (docs/benchmarks.md). One benchmark iteration is the
// scene's whole run (SCENARIOS.md: 600 steps for the stacks and chains), so
// the settling and the resting phase are both in the figure; the counter
// ms_per_step is the mean over the run.
//
//   cairn_bench --benchmark_filter=BM_StepVsBullet
#include "validation/bullet_oracle.hpp"
#include "validation/standard_scenes.hpp"
#include "world/scene.hpp"
#include "world/world.hpp"

#include <benchmark/benchmark.h>

#include <memory>
#include <string>

namespace cairn::bench {
namespace {

const char* const kScenes[] = {"column-10", "pyramid-10", "pyramid-20", "mass-ratio-100", "chain-20",
                               "hinge-pendulum-1.5"};

void BM_StepVsBullet(benchmark::State& state) {
  const validation::StandardScene standard = validation::standardScene(kScenes[state.range(0)]);
  const SceneDesc& scene = standard.scene;
  state.SetLabel(std::string(kScenes[state.range(0)]) + (state.range(1) == 0 ? " cairn" : " bullet"));
  if (state.range(1) == 0) {
    // A fresh world per iteration: every run starts from the scene's start.
    for (auto _ : state) {
      state.PauseTiming();
      World w = buildWorld(scene);
      state.ResumeTiming();
      for (int s = 0; s < scene.steps; ++s) w.step(scene.dt);
    }
  } else {
    for (auto _ : state) {
      state.PauseTiming();
      auto oracle = std::make_unique<validation::BulletOracle>(scene);
      state.ResumeTiming();
      for (int s = 0; s < scene.steps; ++s) oracle->step();
      state.PauseTiming();
      oracle.reset();
      state.ResumeTiming();
    }
  }
  state.counters["ms_per_step"] = benchmark::Counter(double(scene.steps) / 1e3,
                                                     benchmark::Counter::kIsIterationInvariantRate |
                                                         benchmark::Counter::kInvert);
}

BENCHMARK(BM_StepVsBullet)
    ->ArgsProduct({{0, 1, 2, 3, 4, 5}, {0, 1}})
    ->ArgNames({"scene", "bullet"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace
}  // namespace cairn::bench
