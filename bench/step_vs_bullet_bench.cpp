// cairn and Bullet 3.24 (double precision) stepping the same standard scene
// with matched settings (validation/bullet_oracle.hpp, match_cairn), in the
// same process, one after the other: compare the two rows of a scene, not
// absolute times (docs/benchmarks.md). One benchmark iteration is the
// scene's whole run (docs/scenarios.md: 600 steps for the stacks and chains), so
// the settling and the resting phase are both in the figure; the counter
// ms_per_step is the mean over the run.
//
//   cairn_bench --benchmark_filter=BM_StepVsBullet
#include "validation/bullet_oracle.hpp"
#include "validation/standard_scenes.hpp"
#include "cairn/scene.hpp"
#include "world/world_access.hpp"

#include <benchmark/benchmark.h>

#include <memory>
#include <string>

namespace cairn::bench {
namespace {

const char* const kScenes[] = {"column-10", "pyramid-10", "pyramid-20", "mass-ratio-100", "chain-20",
                               "hinge-pendulum-1.5"};

// Arguments: scene index, engine (0 cairn, 1 Bullet), and for cairn an
// iteration count other than the scene's 10 (0: the scene's): cairn at 4
// iterations is as accurate on the stacks as Bullet at 10 (docs/benchmarks.md).
void BM_StepVsBullet(benchmark::State& state) {
  const validation::StandardScene standard = validation::standardScene(kScenes[state.range(0)]);
  SceneDesc scene = standard.scene;
  if (state.range(2) > 0) scene.solver.iterations = static_cast<int>(state.range(2));
  state.SetLabel(std::string(kScenes[state.range(0)]) + (state.range(1) == 0 ? " cairn" : " bullet") + " " +
                 std::to_string(scene.solver.iterations) + " iterations");
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

void stepVsBulletArgs(benchmark::internal::Benchmark* b) {
  for (int engine : {0, 1})
    for (int scene = 0; scene < 6; ++scene) {
      b->Args({scene, engine, 0});
      if (engine == 0 && scene < 4) b->Args({scene, engine, 4});  // the stacks at 4 iterations
    }
}

BENCHMARK(BM_StepVsBullet)
    ->Apply(stepVsBulletArgs)
    ->ArgNames({"scene", "bullet", "iterations"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

}  // namespace
}  // namespace cairn::bench
