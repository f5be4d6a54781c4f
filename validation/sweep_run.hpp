// Running one job of `cairn sweep` and measuring it (docs/tradeoff.md,
// "Columns"): the scene with the job's settings in cairn, or in Bullet,
// measured by the validation code (compare.hpp: Recorder and compareRuns)
// plus the World's LCP residual and the distance from the exact LCP
// solution on sampled steps (lcp_probe.hpp).
#pragma once

#include "validation/compare.hpp"
#include "validation/sweep_plan.hpp"

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace cairn::validation {

// The measured columns of the table, in order. Units are in the names.
enum class Measure {
  MsPerStep,         // wall time of World::step (Bullet: of its step), median over the run's steps (ms)
  Penetration,       // deepest geometric penetration over the whole run (m)
  JointError,        // largest linear joint error over the run (m)
  JointAngleError,   // largest angular joint error over the run (rad)
  Residual,          // largest natural-map LCP residual of a step (StepStats::residual)
  EnergyDrift,       // largest |E - E0| of kinetic + potential energy over the run (J, absolute)
  // Mean over the sampled steps (lcp_probe.hpp), not the largest: runs with
  // different settings follow different trajectories, and the worst step
  // of a whipping chain says more about the trajectory than the solver.
  ExactDistance,     // |lambda - lambda*| / max(|lambda|, |lambda*|)
  ExactVelocity,     // the same for the velocity change J^T lambda, kinetic-energy norm (read this one for stacks)
  BulletPosition,    // trajectory scenes: largest position difference from Bullet at the same settings (m)
  Drift,             // statistics scenes: largest displacement of a body at the end (m)
  AnalyticError,     // the scene's first closed form (SweepRunner::analyticName)
  Count
};
inline constexpr int kMeasureCount = static_cast<int>(Measure::Count);
const char* measureColumn(Measure m);  // "ms_per_step", "penetration_m", ...
std::optional<Measure> measureByColumn(const std::string& column);

struct SweepRow {
  int index = 0;
  bool bullet = false;
  std::vector<std::string> settings;  // SweepPlan::columns
  std::array<std::optional<double>, kMeasureCount> values{};
  bool pareto = false;
  std::string status = "ok";  // or why the run stopped (non-finite state)
  std::string notes;          // why a figure is missing (the exact distance)
  const std::optional<double>& operator[](Measure m) const { return values[size_t(m)]; }
};

class SweepRunner {
 public:
  // exact_every: sample the exact LCP distance every K-th step (0: never).
  SweepRunner(const SceneDesc& base, const SweepPlan& plan, int exact_every);
  SweepRow run(const SweepJob& job);

  const ValidationSpec& spec() const { return spec_; }
  // "period (relative)" etc.; "" when the scene has no closed form.
  const std::string& analyticName() const { return analytic_name_; }

 private:
  const EngineRun& bulletRun(int job);

  const SceneDesc& base_;
  const SweepPlan& plan_;
  int exact_every_;
  ValidationSpec spec_;
  std::string analytic_name_;
  std::map<int, EngineRun> bullet_runs_;  // by job index: each distinct Bullet setting runs once
};

// The error column that ranks a scene's settings by default: joint error
// for scenes with joints, penetration where bodies touch, else energy drift.
Measure defaultParetoAxis(const SceneDesc& scene, const ValidationSpec& spec);

}  // namespace cairn::validation
