// `cairn run SCENE.json [--steps N] [--dt H] [--out traj.csv] [--every K]
//  [--metrics m.json] [--method auto|pgs|direct|lcp] [--substeps N]
//  [--iterations N] [--limit NAME=N ...] [--save-state FILE]`: simulate a
// scene and write its trajectory; `cairn run --restore FILE --steps N [...]`
// goes on from a snapshot that --save-state wrote (docs/snapshots.md),
// bit-identically. Trajectory rows are numbered by the world's step count,
// so a restored run's rows continue the saved run's.
//
// Everything that can be checked is checked before the first step: the
// scene (with the input limits), the overrides, and the output paths (not
// a directory, not the same file twice, not the scene itself, in a
// directory that takes a new file: the output files are created there
// before the run). The trajectory is streamed to its temporary file as the
// run goes, so memory stays flat however long the run; both files replace
// their targets only when the run succeeded (validation/output_file.hpp).
#include "cli/commands.hpp"
#include "cli/solver_overrides.hpp"
#include "cairn/error.hpp"
#include "validation/csv.hpp"
#include "validation/output_file.hpp"
#include "world/def_checks.hpp"
#include "world/scene_json.hpp"
#include "world/world_access.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace cairn::cli {

namespace {

struct RunOptions {
  std::string scene;
  std::string restore, save_state;
  std::optional<int> steps;
  std::optional<double> dt;
  std::string out;
  int every = 1;
  std::string metrics;
  SolverOverrides solver;
  std::vector<std::string> limits;  // NAME=VALUE
};

// A figure for the metrics file: a JSON number when finite; JSON has no
// spelling for infinity or NaN (nlohmann would write null), so those are
// the strings "inf", "-inf" and "nan" (docs/reliability.md).
nlohmann::json figure(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
}

// Figures gathered over a run for the metrics file.
struct RunFigures {
  long iterations = 0;
  Real residual_max = 0, residual_final = 0;
  Real joint_linear_max = 0, joint_angular_max = 0;
  int rows_max = 0;
  int rows_by_kind_max[kRowKindCount] = {};
  std::vector<std::string> broken;
  int contacts_max = 0, islands_max = 0, contacts_final = 0;
  Real penetration_last_second = 0;
  Real last_second_from = 0;  // time at which the last second of the run starts
  double stage_seconds[kStageCount] = {};  // summed over the run
  // Energy through the run (StepStats::energy): its extremes over every
  // step, and every energy_every-th step's value, at most 1,000 of them
  // whatever the run's length.
  int energy_every = 1;
  Real energy_min = kInf, energy_max = -kInf;
  std::vector<Real> energy;
  // Island-steps per solver method and per reason (world/method_choice.cpp).
  long islands_by_method[kSolverMethodCount] = {};
  long islands_by_reason[kMethodReasonCount] = {};
  long position_iterations = 0;
  Real position_error_max = 0;

  void record(const World& w) {
    const StepStats& st = w.lastStepStats();
    energy_min = std::min(energy_min, st.energy);
    energy_max = std::max(energy_max, st.energy);
    if (w.stepCount() % energy_every == 0) energy.push_back(st.energy);
    contacts_max = std::max(contacts_max, st.contacts);
    contacts_final = st.contacts;
    islands_max = std::max(islands_max, st.islands);
    if (w.time() >= last_second_from - 1e-12) penetration_last_second = std::max(penetration_last_second, st.max_penetration);
    iterations += st.iterations;
    for (int k = 0; k < kStageCount; ++k) stage_seconds[k] += st.stage_seconds[k];
    for (int k = 0; k < kSolverMethodCount; ++k) islands_by_method[k] += st.islands_by_method[k];
    for (int k = 0; k < kMethodReasonCount; ++k) islands_by_reason[k] += st.islands_by_reason[k];
    position_iterations += st.position_iterations;
    position_error_max = std::max(position_error_max, st.position_error);
    residual_final = st.residual;
    residual_max = std::max(residual_max, st.residual);
    rows_max = std::max(rows_max, st.rows);
    for (int k = 0; k < kRowKindCount; ++k) rows_by_kind_max[k] = std::max(rows_by_kind_max[k], st.rows_by_kind[k]);
    for (int j = 0; j < cairn::detail::internals(w).jointSlots(); ++j) {
      const JointError e = w.jointError(JointId{j});
      joint_linear_max = std::max(joint_linear_max, e.linear);
      joint_angular_max = std::max(joint_angular_max, e.angular);
    }
    for (const auto& e : w.jointBreakEvents()) broken.push_back(e.name);
  }

  void write(nlohmann::json& m, const World& w) const {
    const int steps = std::max(1, w.stepCount());
    m["iterations_total"] = iterations;
    m["iterations_per_step"] = double(iterations) / steps;
    m["residual_final"] = figure(residual_final);
    m["residual_max"] = figure(residual_max);
    m["residual_definition"] = "max_i |lambda_i - clamp(lambda_i - w_i, lo_i, hi_i)|, w = J v - rhs + cfm lambda";
    m["rows_max"] = rows_max;
    nlohmann::json kinds = nlohmann::json::object();
    for (int k = 0; k < kRowKindCount; ++k) kinds[rowKindName(static_cast<RowKind>(k))] = rows_by_kind_max[k];
    m["rows_by_kind_max"] = kinds;
    m["joint_count"] = cairn::detail::internals(w).jointSlots();
    m["joint_error_linear_max_m"] = figure(joint_linear_max);
    m["joint_error_angular_max_rad"] = figure(joint_angular_max);
    m["joints_broken"] = broken;
    m["contacts_max"] = contacts_max;
    m["contacts_final"] = contacts_final;
    m["islands_max"] = islands_max;
    m["penetration_last_second_max_m"] = figure(penetration_last_second);
    nlohmann::json stages = nlohmann::json::object();  // wall ms per step, by stage of the step
    for (int k = 0; k < kStageCount; ++k) stages[stageName(static_cast<Stage>(k))] = 1e3 * stage_seconds[k] / steps;
    m["stage_ms_per_step"] = stages;
    m["energy_min"] = figure(w.stepCount() ? energy_min : 0.0);
    m["energy_max"] = figure(w.stepCount() ? energy_max : 0.0);
    m["energy_every"] = energy_every;
    nlohmann::json series = nlohmann::json::array();
    for (const Real e : energy) series.push_back(figure(e));
    m["energy"] = series;
    nlohmann::json by_method = nlohmann::json::object(), by_reason = nlohmann::json::object();
    for (int k = 0; k < kSolverMethodCount; ++k)
      if (islands_by_method[k] > 0) by_method[solverMethodName(static_cast<SolverMethod>(k))] = islands_by_method[k];
    for (int k = 0; k < kMethodReasonCount; ++k)
      if (islands_by_reason[k] > 0) by_reason[methodReasonName(static_cast<MethodReason>(k))] = islands_by_reason[k];
    m["island_steps_by_method"] = by_method;
    m["island_steps_by_reason"] = by_reason;
    m["position_pass_iterations_total"] = position_iterations;
    m["position_pass_error_max"] = position_error_max;
  }

  // "pgs 540, direct 60 (mass_ratio 60)": what solved the islands, and why.
  std::string islandSummary() const {
    std::string s;
    for (int k = 0; k < kSolverMethodCount; ++k)
      if (islands_by_method[k] > 0)
        s += std::string(s.empty() ? "" : ", ") + solverMethodName(static_cast<SolverMethod>(k)) + " " +
             std::to_string(islands_by_method[k]);
    std::string why;
    for (int k = 0; k < kMethodReasonCount; ++k)
      if (islands_by_reason[k] > 0)
        why += std::string(why.empty() ? "" : ", ") + methodReasonName(static_cast<MethodReason>(k)) + " " +
               std::to_string(islands_by_reason[k]);
    return s.empty() ? "no islands" : s + " (" + why + ")";
  }
};

// One row per non-static body: step, time, name, position, orientation,
// linear and angular velocity.
void writeRows(validation::OutputFile& out, validation::CsvRecord& row, const World& w, int step) {
  for (const Body& b : cairn::detail::internals(w).bodies()) {
    if (b.type == BodyType::Static) continue;
    row.clear();
    row.integer(step).number(w.time()).text(b.name);
    for (double v : {b.position.x(), b.position.y(), b.position.z(), b.orientation.w(), b.orientation.x(),
                     b.orientation.y(), b.orientation.z(), b.linear_velocity.x(), b.linear_velocity.y(),
                     b.linear_velocity.z(), b.angular_velocity.x(), b.angular_velocity.y(), b.angular_velocity.z()})
      row.number(v);
    out.write(row.line());
  }
}

int runScene(const RunOptions& opt) {
  SceneDesc scene;
  std::unique_ptr<validation::OutputFile> traj, metrics;
  World world;
  const std::string& source = opt.restore.empty() ? opt.scene : opt.restore;
  try {
    InputLimits limits;
    for (const std::string& l : opt.limits) setInputLimit(limits, l);
    if (opt.scene.empty() == opt.restore.empty()) throw InputError("", "", "give a scene file or --restore FILE (one of them)");
    if (!opt.restore.empty()) {
      // The snapshot's world, its settings and its last step size.
      if (!opt.steps) throw InputError("--steps", "", "is required with --restore");
      world.restoreSnapshot(opt.restore);
      scene.solver = world.settings();
      scene.dt = cairn::detail::internals(world).stepContext().h;
      if (!(scene.dt > 0) && !opt.dt) throw InputError("--dt", "", "is required: the snapshot was taken before any step");
    } else {
      scene = loadScene(opt.scene, limits);
    }
    if (opt.steps) {
      if (*opt.steps < 0) throw InputError("--steps", "", "must be >= 0");
      scene.steps = *opt.steps;
    }
    if (opt.dt) {
      if (!(*opt.dt >= kMinSize && *opt.dt <= kMaxMagnitude)) {
        std::ostringstream range;
        range << "must lie in [" << kMinSize << ", " << kMaxMagnitude << "] s (docs/reliability.md)";
        throw InputError("--dt", "", range.str());
      }
      scene.dt = *opt.dt;
    }
    if (opt.every < 1) throw InputError("--every", "", "must be >= 1");
    applySolverOverrides(opt.solver, scene);
    checkSolverSettings(scene.solver, limits);
    validation::checkOutputPaths({{"--out", opt.out}, {"--metrics", opt.metrics}, {"--save-state", opt.save_state}},
                                 {source});
    if (opt.restore.empty()) world = buildWorld(scene);
    else world.setSettings(scene.solver);
    if (!opt.out.empty()) traj = std::make_unique<validation::OutputFile>(opt.out);
    if (!opt.metrics.empty()) metrics = std::make_unique<validation::OutputFile>(opt.metrics);
  } catch (const InputError& e) {
    std::cerr << "cairn run: " << e.what() << "\n";
    return 2;
  }

  validation::CsvRecord row;
  if (traj) {
    traj->write(validation::csvRecord({"step", "time", "body", "px", "py", "pz", "qw", "qx", "qy", "qz", "vx", "vy",
                                       "vz", "wx", "wy", "wz"}));
    writeRows(*traj, row, world, world.stepCount());
  }
  const int first_step = world.stepCount();  // 0, or the snapshot's
  const Real e0 = world.kineticEnergy() + world.potentialEnergy();
  RunFigures fig;
  fig.last_second_from = world.time() + scene.steps * scene.dt - 1;
  fig.energy_every = static_cast<int>(std::max<long long>(1, (static_cast<long long>(scene.steps) + 999) / 1000));
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  for (int s = 1; s <= scene.steps; ++s) {
    world.step(scene.dt);
    fig.record(world);
    if (!world.numericalEvents().empty()) {
      const auto& ev = world.numericalEvents().front();
      std::cerr << "cairn run: " << source << ": body '" << ev.body_name << "': non-finite state in "
                << ev.stage << " at step " << world.stepCount() << "; stopped\n";
      status = 3;
      break;
    }
    if (traj && s % opt.every == 0) writeRows(*traj, row, world, world.stepCount());
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // On stderr the first 20 (a pile of coincident bodies reports each one);
  // the metrics hold them all.
  const auto diagnostics = world.diagnostics();
  for (size_t i = 0; i < std::min<size_t>(diagnostics.size(), 20); ++i) {
    const Diagnostic& d = diagnostics[i];
    std::cerr << "cairn run: " << source << ": body '" << d.body_name << "': " << d.kind << " in " << d.count
              << " (sub)steps from step " << d.first_step + 1 << ": " << d.detail << "\n";
  }
  if (diagnostics.size() > 20)
    std::cerr << "cairn run: " << source << ": " << diagnostics.size() - 20
              << " more diagnostics (all in the metrics)\n";
  if (status != 0) return status;  // the output files are removed unwritten
  if (!opt.save_state.empty()) {
    try {
      world.saveSnapshot(opt.save_state);
    } catch (const InputError& e) {
      std::cerr << "cairn run: " << e.what() << "\n";
      return 2;
    }
  }

  if (metrics) {
    nlohmann::json m;
    m["scene"] = source;
    m["steps"] = world.stepCount();
    m["dt"] = scene.dt;
    m["method"] = solverMethodName(scene.solver.method);
    m["substeps"] = scene.solver.substeps;
    m["iterations"] = scene.solver.iterations;
    m["body_count"] = world.bodyCount();
    m["wall_time_s"] = wall;
    m["wall_time_per_step_ms"] = world.stepCount() > first_step ? 1e3 * wall / (world.stepCount() - first_step) : 0.0;
    m["energy_initial"] = figure(e0);
    nlohmann::json diags = nlohmann::json::array();
    for (const Diagnostic& d : world.diagnostics())
      diags.push_back({{"body", d.body_name}, {"kind", d.kind}, {"detail", d.detail}, {"first_step", d.first_step + 1},
                       {"count", d.count}});
    m["diagnostics"] = diags;
    m["energy_final"] = figure(world.kineticEnergy() + world.potentialEnergy());
    fig.write(m, world);
    // The scene path comes from the command line and may not be UTF-8.
    metrics->write(m.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  }
  // Both files are complete before either replaces its target.
  if (traj) traj->finish();
  if (metrics) metrics->finish();
  if (traj) traj->commit();
  if (metrics) metrics->commit();
  std::cout << source << ": " << world.stepCount() << " steps of " << scene.dt << " s, "
            << world.bodyCount() << " bodies, " << 1e3 * wall / std::max(1, world.stepCount() - first_step)
            << " ms/step\n"
            << "  island-steps by solver: " << fig.islandSummary() << "; largest joint error "
            << fig.joint_linear_max << " m\n";
  return 0;
}

}  // namespace

void addRunCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* run = app.add_subcommand("run", "Simulate a scene file and write its trajectory");
  run->add_option("scene", opt->scene, "Scene JSON file (or --restore)");
  run->add_option("--steps", opt->steps, "Number of steps (overrides the file)");
  run->add_option("--dt", opt->dt, "Time step in seconds (overrides the file)");
  run->add_option("--out", opt->out, "Trajectory CSV to write");
  run->add_option("--every", opt->every, "Record every K-th step (default 1)");
  run->add_option("--metrics", opt->metrics, "Metrics JSON to write");
  run->add_option("--save-state", opt->save_state, "Snapshot of the world after the run to write");
  run->add_option("--restore", opt->restore, "Go on from this snapshot instead of a scene (needs --steps)");
  addSolverOverrideOptions(*run, opt->solver);
  run->add_option("--limit", opt->limits,
                  "Raise or lower an input limit, NAME=N (repeatable; docs/reliability.md lists them)");
  run->callback([opt, &status] { status = runScene(*opt); });
}

}  // namespace cairn::cli
