// The jobs of `cairn sweep` (docs/tradeoff.md): the cartesian product of
// the --vary lists, then one Bullet job per distinct setting Bullet can
// see, each with a fixed index so that shards and merges agree.
//
// Order: the first --vary key is the outermost loop, the last the
// innermost; values in the order written. Jobs 0 .. C-1 are cairn's
// combinations in that order; jobs C .. C+B-1 are Bullet's, one per
// distinct combination of the settings Bullet sees, in order of first
// appearance: all but `method` (Bullet has one solver) and `nncg` (no
// Bullet counterpart), which its rows show as "bullet" and "-". The
// oracle runs `substeps` Bullet steps of dt/substeps per step, so
// substeps do reach Bullet.
//
// A shard i/n (0 <= i < n) runs the jobs whose index % n == i.
#pragma once

#include "cairn/scene.hpp"

#include <string>
#include <vector>

namespace cairn::validation {

struct VaryAxis {
  std::string key;
  std::vector<std::string> values;  // canonical text (numbers round-trip exactly)
};

// "iterations=1,2,4" -> {iterations, {1, 2, 4}}; "iterations=1,2,4,...,200"
// -> {1, 2, 4, 8, 16, 32, 64, 128, 200} (the progression the values before
// "..." start -- geometric when three share a ratio, else arithmetic --
// continued below the last value, then the last value). Each value checked on
// `scene` (validation/solver_keys.hpp). Throws InputError naming --vary and
// the key or value.
VaryAxis parseVary(const std::string& arg, const SceneDesc& scene);

struct SweepJob {
  int index = 0;
  bool bullet = false;
  // One value per setting column (SweepPlan::columns); a Bullet job has
  // "bullet" as its method and "-" for settings Bullet does not see.
  std::vector<std::string> settings;
};

struct SweepPlan {
  std::vector<VaryAxis> axes;
  // Setting columns: method, substeps, iterations, erp, dt, then any other
  // varied key (solver_keys.hpp order).
  std::vector<std::string> columns;
  std::vector<SweepJob> jobs;  // by index
  int cairn_jobs = 0;
};

// Throws InputError when a key is varied twice or a list repeats a value.
SweepPlan makeSweepPlan(const std::vector<VaryAxis>& axes, const SceneDesc& scene);

// The scene a job runs: the base scene with the job's settings. When dt
// differs from the base scene's, the step count is scaled so that every
// job covers the same simulated time.
SceneDesc jobScene(const SweepPlan& plan, const SweepJob& job, const SceneDesc& base);

// The Bullet job (index) whose run is the reference for cairn job `job`.
int bulletJobFor(const SweepPlan& plan, const SweepJob& job);

struct Shard {
  int index = 0, count = 1;
  bool whole() const { return count == 1; }
  bool owns(int job) const { return job % count == index; }
};

// "i/n" with integers 0 <= i < n; throws InputError naming --shard.
Shard parseShard(const std::string& text);

}  // namespace cairn::validation
