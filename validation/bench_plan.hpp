// What `cairn bench` runs (docs/benchmarks.md, "cairn bench"): its default
// scene list, the scaling series, and each scene as each engine
// configuration sees it after the command's overrides.
//
// Overrides are KEY=VALUE with the keys of the scene file's "solver" block
// plus dt (validation/solver_keys.hpp, as `cairn sweep --vary`), applied in
// this order:
//   --set          every engine; a new dt scales the step count so the run
//                  covers the same simulated time
//   --steps N      every engine's step count
//   --cairn-set    cairn only (e.g. iterations=4: equal accuracy at less cost)
//   --bullet-set   both Bullet configurations
//   --threads N    cairn's SolverSettings::threads
// Bullet's defaults keep Bullet's own deactivation unless sleeping is
// overridden for them (--set or --bullet-set): then they follow the
// scene's sleeping as the matched configuration does (sleeping=false keeps
// Bullet awake, to time its solver rather than its sleeping).
// dt is refused in --cairn-set and --bullet-set: the engines are compared
// step for step, and the exact solve is one ruler for all of them.
#pragma once

#include "validation/bench_run.hpp"

#include <optional>
#include <string>
#include <vector>

namespace cairn::validation {

struct BenchOverrides {
  std::vector<std::string> all, cairn, bullet;  // KEY=VALUE
  std::optional<int> steps;
  int threads = 1;
};

// A scene of a list: a standard scenario key and its step count (0: the
// scenario's own).
struct ListedScene {
  std::string key;
  int steps = 0;
};

// pyramid-20, pile-1000, chain-100, ragdoll, column-20 and mass-ratio-100
// for their own runs (600 steps, the ragdoll 300), and pyramid-100 for 200
// steps, as Box3D's benchmark runs its large pyramid.
const std::vector<ListedScene>& defaultBenchScenes();

// The scaling series: pyramids of base 10, 20, 40 and 100, piles of 125,
// 1,000 and 8,000 boxes, chains of 10, 100 and 1,000 links, each family
// run for one step count (the same simulated time for every size, so that
// settling and Bullet's deactivation play the same part at every size).
const std::vector<ListedScene>& scalingSeries();

// Throws InputError naming the option when a count is below 1.
void checkBenchCounts(const BenchOverrides& o, int repeats);

// `scene` (named `name`) as each configuration runs it. Throws InputError
// naming the option when an override is malformed, unknown or out of range.
BenchScene makeBenchScene(const std::string& name, const SceneDesc& scene, const BenchOverrides& o);

}  // namespace cairn::validation
