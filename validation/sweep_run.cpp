#include "validation/sweep_run.hpp"

#include "validation/lcp_probe.hpp"

#include <algorithm>
#include <cmath>

namespace cairn::validation {

namespace {

constexpr const char* kColumns[kMeasureCount] = {
    "ms_per_step",        "penetration_m",           "joint_error_m",          "joint_angle_error_rad",
    "lcp_residual",       "energy_drift_j",          "exact_lcp_distance",     "exact_velocity_distance",
    "bullet_position_diff_m", "drift_m",             "analytic_error",
};

// The closed form a scene's analytic_error column reads: compareRuns's
// figure key, and whether the error is relative (|value / exact - 1|) or
// absolute (|value - exact|, in the figure's unit).
struct AnalyticColumn {
  std::string key;
  bool relative = false;
  std::string unit;
};

std::optional<AnalyticColumn> analyticColumn(const ValidationSpec& spec) {
  if (!spec.analytic.empty()) {
    const std::string& t = spec.analytic.front().type;
    if (t == "pendulum_period") return AnalyticColumn{"period", true, ""};
    if (t == "spring_period") return AnalyticColumn{"spring_period", true, ""};
    if (t == "torque_free") return AnalyticColumn{"torque_free", true, ""};
    if (t == "slide") return AnalyticColumn{"slide", false, "m/s^2"};
    if (t == "stick" || t == "projectile") return AnalyticColumn{t, false, "m"};
    if (t == "apex_ratio") return AnalyticColumn{"apex_ratio", false, ""};
    if (t == "open_time") return AnalyticColumn{"open_time", false, "s"};
  }
  // Stacks: the top box's height at the end against the height it was
  // stacked at (how far the stack sank).
  if (spec.kind == ValidationKind::Statistics &&
      (spec.scenario == "pyramid" || spec.scenario == "column" || spec.scenario == "mass-ratio"))
    return AnalyticColumn{"top_height", false, "m"};
  return std::nullopt;
}

const Figure* findFigure(const std::vector<Figure>& figs, const std::string& key) {
  for (const Figure& f : figs)
    if (f.key == key) return &f;
  return nullptr;
}

std::optional<double> figureValue(const std::vector<Figure>& figs, const std::string& key) {
  const Figure* f = findFigure(figs, key);
  return f ? f->cairn : std::nullopt;
}

// One line of text for a table cell (the Markdown table has one row per
// line; the CSV writer quotes whatever else the text holds).
std::string cell(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s;
}

// Figures of one engine's run, read from compareRuns (figures[].cairn is
// the run passed first) and the run itself.
void fill(SweepRow& row, const SceneDesc& scene, const ValidationSpec& spec, const EngineRun& run,
          const EngineRun& reference) {
  const std::vector<Figure> figs = compareRuns(scene, spec, run, reference);
  const auto set = [&](Measure m, std::optional<double> v) {
    if (v && std::isfinite(*v)) row.values[size_t(m)] = v;
  };
  // The median step, not compareRuns's mean: on a machine shared with other
  // work a few descheduled steps would otherwise decide the ranking.
  if (run.step_seconds.size() > 1) {
    std::vector<double> sec(run.step_seconds.begin() + 1, run.step_seconds.end());
    std::nth_element(sec.begin(), sec.begin() + long(sec.size() / 2), sec.end());
    set(Measure::MsPerStep, 1e3 * sec[sec.size() / 2]);
  }
  if (!run.penetration.empty()) set(Measure::Penetration, *std::max_element(run.penetration.begin(), run.penetration.end()));
  set(Measure::JointError, figureValue(figs, "joint_error"));
  set(Measure::JointAngleError, figureValue(figs, "joint_angle_error"));
  set(Measure::EnergyDrift, figureValue(figs, "energy"));
  set(Measure::BulletPosition, figureValue(figs, "position"));
  set(Measure::Drift, figureValue(figs, "drift"));
  if (const auto a = analyticColumn(spec)) {
    const Figure* f = findFigure(figs, a->key);
    if (f && f->cairn && f->analytic)
      set(Measure::AnalyticError, a->relative ? std::abs(*f->cairn / *f->analytic - 1) : std::abs(*f->cairn - *f->analytic));
  }
  if (!run.failure.empty()) row.status = "stopped: " + cell(run.failure);
}

}  // namespace

const char* measureColumn(Measure m) { return kColumns[size_t(m)]; }

std::optional<Measure> measureByColumn(const std::string& column) {
  for (int i = 0; i < kMeasureCount; ++i)
    if (column == kColumns[i]) return static_cast<Measure>(i);
  return std::nullopt;
}

Measure defaultParetoAxis(const SceneDesc& scene, const ValidationSpec& spec) {
  if (!scene.joints.empty()) return Measure::JointError;
  if (spec.kind == ValidationKind::Statistics) return Measure::Penetration;
  return Measure::EnergyDrift;
}

SweepRunner::SweepRunner(const SceneDesc& base, const SweepPlan& plan, int exact_every)
    : base_(base), plan_(plan), exact_every_(exact_every), spec_(validationSpec(base)) {
  if (const auto a = analyticColumn(spec_))
    analytic_name_ = a->key + (a->relative ? " (relative)" : a->unit.empty() ? " (absolute)" : " (" + a->unit + ")");
}

const EngineRun& SweepRunner::bulletRun(int job) {
  auto it = bullet_runs_.find(job);
  if (it != bullet_runs_.end()) return it->second;
  const SceneDesc scene = jobScene(plan_, plan_.jobs[size_t(job)], base_);
  EngineRun& run = bullet_runs_[job];
  BulletRunner bullet(scene, spec_, run);
  for (int s = 1; s <= scene.steps && bullet.step(s); ++s) {
  }
  return run;
}

SweepRow SweepRunner::run(const SweepJob& job) {
  SweepRow row;
  row.index = job.index;
  row.bullet = job.bullet;
  row.settings = job.settings;
  const SceneDesc scene = jobScene(plan_, job, base_);
  if (job.bullet) {
    fill(row, scene, spec_, bulletRun(job.index), EngineRun{});
    return row;
  }

  EngineRun run;
  CairnRunner cairn(scene, spec_, run);
  ExactLcpProbe probe;
  double residual = 0, distance = 0, velocity = 0;
  int sampled = 0, unmeasured = 0;
  std::string why;
  for (int s = 1; s <= scene.steps; ++s) {
    const bool sample = exact_every_ > 0 && s % exact_every_ == 0;
    if (sample) probe.beforeStep(cairn.world());
    if (!cairn.step(s)) break;
    residual = std::max(residual, double(cairn.world().lastStepStats().residual));
    if (!sample) continue;
    if (const auto d = probe.afterStep(cairn.world(), scene.dt)) {
      distance += d->lambda;
      velocity += d->velocity;
      ++sampled;
    } else {
      if (why.empty()) why = probe.why();
      ++unmeasured;
    }
  }
  const int bullet_job = bulletJobFor(plan_, job);
  fill(row, scene, spec_, run, bullet_job >= 0 ? bulletRun(bullet_job) : EngineRun{});
  if (run.samples() > 1) row.values[size_t(Measure::Residual)] = residual;
  if (sampled > 0) {
    row.values[size_t(Measure::ExactDistance)] = distance / sampled;
    row.values[size_t(Measure::ExactVelocity)] = velocity / sampled;
  }
  if (sampled == 0 && exact_every_ > 0)
    row.notes = "no exact LCP distance: " + cell(why.empty() ? "no step sampled" : why);
  else if (unmeasured > 0)
    row.notes = "exact LCP distance over " + std::to_string(sampled) + " of " + std::to_string(sampled + unmeasured) +
                " sampled steps; the others: " + cell(why);
  return row;
}

}  // namespace cairn::validation
