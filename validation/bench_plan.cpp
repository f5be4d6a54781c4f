#include "validation/bench_plan.hpp"

#include "cairn/error.hpp"
#include "validation/compare.hpp"
#include "validation/solver_keys.hpp"

#include <algorithm>
#include <cmath>

namespace cairn::validation {

namespace {

// Applies "KEY=VALUE" to `scene`; returns the canonical "KEY=VALUE".
std::string applySetting(SceneDesc& scene, const std::string& text, const std::string& option, bool dt_allowed) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError(option, "", "expected KEY=VALUE (got '" + text + "')");
  const std::string key = text.substr(0, eq);
  if (key == "dt" && !dt_allowed)
    throw InputError(option, "", "dt must be the same for every engine: give it with --set");
  setSolverKey(scene, key, text.substr(eq + 1), option + " " + key);
  return key + "=" + solverKeyValue(scene, key);
}

std::string joined(const std::vector<std::string>& parts) {
  std::string s;
  for (const std::string& p : parts) s += (s.empty() ? "" : " ") + p;
  return s;
}

}  // namespace

const std::vector<ListedScene>& defaultBenchScenes() {
  // The large pyramid costs about a hundred times pyramid-20 per step: 200
  // steps (Box3D's benchmark/main.c runs large_pyramid for 200) keep a
  // default run of three repeats within minutes.
  static const std::vector<ListedScene> list = {{"pyramid-20", 0}, {"pile-1000", 0},      {"chain-100", 0},
                                                {"ragdoll", 0},    {"column-20", 0},      {"mass-ratio-100", 0},
                                                {"pyramid-100", 200}};
  return list;
}

const std::vector<ListedScene>& scalingSeries() {
  // 100 steps (1.67 s): the largest sizes finish in seconds, and no size
  // runs long enough for Bullet's default deactivation (2 s at rest) to
  // start. Piles run 150 steps (2.5 s) so that the 20-layer pile has landed.
  static const std::vector<ListedScene> series = {
      {"pyramid-10", 100}, {"pyramid-20", 100}, {"pyramid-40", 100}, {"pyramid-100", 100},
      {"pile-125", 150},   {"pile-1000", 150},  {"pile-8000", 150},
      {"chain-10", 100},   {"chain-100", 100},  {"chain-1000", 100},
  };
  return series;
}

void checkBenchCounts(const BenchOverrides& o, int repeats) {
  if (repeats < 1) throw InputError("--repeat", "", "must be >= 1 (got " + std::to_string(repeats) + ")");
  if (o.steps && *o.steps < 1) throw InputError("--steps", "", "must be >= 1 (got " + std::to_string(*o.steps) + ")");
  if (o.threads < 1) throw InputError("--threads", "", "must be >= 1 (got " + std::to_string(o.threads) + ")");
}

BenchScene makeBenchScene(const std::string& name, const SceneDesc& scene, const BenchOverrides& o) {
  BenchScene b;
  b.name = name;
  b.base = scene;
  std::vector<std::string> common;
  for (const std::string& s : o.all) common.push_back(applySetting(b.base, s, "--set", true));
  if (b.base.dt != scene.dt) b.base.steps = std::max(1, int(std::lround(scene.steps * scene.dt / b.base.dt)));
  if (o.steps) {
    b.base.steps = *o.steps;
    common.push_back("steps=" + std::to_string(*o.steps));
  }
  const ValidationSpec spec = validationSpec(b.base);
  b.family = spec.scenario.empty() ? name : spec.scenario;
  for (int i = 0; i < kBenchEngineCount; ++i) {
    const BenchEngine e = benchEngine(i);
    SceneDesc& s = b.scenes[size_t(i)];
    s = b.base;
    std::vector<std::string> applied = common;
    const bool cairn = e == BenchEngine::Cairn;
    for (const std::string& t : cairn ? o.cairn : o.bullet)
      applied.push_back(applySetting(s, t, cairn ? "--cairn-set" : "--bullet-set", false));
    if (cairn) s.solver.threads = o.threads;
    const bool sleeping_set = std::any_of(applied.begin(), applied.end(),
                                          [](const std::string& a) { return a.rfind("sleeping=", 0) == 0; });
    b.oracle[size_t(i)].match_cairn = e != BenchEngine::BulletDefaults;
    b.oracle[size_t(i)].bullet_deactivation = e == BenchEngine::BulletDefaults && !sleeping_set;
    b.overrides[size_t(i)] = joined(applied);
  }
  return b;
}

}  // namespace cairn::validation
