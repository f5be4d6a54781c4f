// `cairn sweep SCENE --vary KEY=V1,V2,... [--vary ...] [--out DIR]
//  [--shard i/n] [--steps N] [--exact-every K] [--pareto-axis COLUMN]`
// `cairn sweep --merge DIR... --out DIR`
//
// Runs SCENE (a scene file or a standard scenario key) once per
// combination of the --vary lists, and Bullet once per distinct setting it
// can see, and writes DIR/sweep.csv, sweep.md, sweep.json and pareto.png:
// wall time per step against the accuracy figures, with the
// Pareto-optimal settings marked (validation/sweep_*.hpp, docs/tradeoff.md),
// and DIR/replay.html: the scene with its own settings in cairn and Bullet,
// in 3D (docs/viewer.md; written by shard 0, copied by --merge).
// --shard i/n (0-based) runs every n-th job from the i-th; --merge joins
// the parts' directories into one sweep.
//
// Exit status: 0 written; 2 bad input (an unknown key or bad value, a bad
// shard, parts that do not belong together), with one line on stderr
// naming it and nothing written.
#include "cli/commands.hpp"
#include "cli/scene_arg.hpp"
#include "cairn/error.hpp"
#include "validation/plot_script.hpp"
#include "validation/replay_page.hpp"
#include "validation/report.hpp"
#include "validation/scene_writer.hpp"
#include "validation/sweep_table.hpp"

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace cairn::cli {

namespace {

namespace fs = std::filesystem;
using namespace validation;
using Json = nlohmann::ordered_json;

struct SweepOptions {
  std::string scene;
  std::vector<std::string> vary;
  std::string out = "sweep";
  std::optional<std::string> shard;
  std::optional<int> steps;
  std::optional<int> exact_every;
  std::optional<std::string> pareto_axis;
  std::vector<std::string> merge;
};

std::string quoteCommand(const SweepOptions& o) {
  std::string cmd = "cairn sweep";
  if (!o.merge.empty()) {
    cmd += " --merge";
    for (const auto& d : o.merge) cmd += " " + d;
  } else {
    cmd += " " + o.scene;
    for (const auto& v : o.vary) cmd += " --vary " + v;
    if (o.steps) cmd += " --steps " + std::to_string(*o.steps);
    if (o.exact_every) cmd += " --exact-every " + std::to_string(*o.exact_every);
    if (o.pareto_axis) cmd += " --pareto-axis " + *o.pareto_axis;
    if (o.shard) cmd += " --shard " + *o.shard;
  }
  return cmd + " --out " + o.out;
}

// Draws DIR/pareto.png; a warning on stderr when it cannot (the tables are
// written regardless, as `cairn validate --report` does).
void drawPlot(const std::string& dir) {
  const std::string script = findPlotScript("plot_sweep.py");
  const std::string warning = script.empty() ? "validation/plot_sweep.py not found; pareto.png not drawn"
                                             : runPlotScript("/usr/bin/python3", script, dir);
  if (!warning.empty()) std::cerr << "cairn sweep: warning: " << warning << "\n";
}

std::string errorColumns() {
  std::string s;
  for (int m = 1; m < kMeasureCount; ++m) s += std::string(s.empty() ? "" : ", ") + measureColumn(static_cast<Measure>(m));
  return s;
}

int merge(const SweepOptions& o) {
  SweepTable whole;
  try {
    if (!o.scene.empty() || !o.vary.empty() || o.shard || o.steps || o.exact_every || o.pareto_axis)
      throw InputError("--merge", "", "joins finished parts: give only the part directories and --out");
    std::vector<SweepTable> parts;
    for (const std::string& d : o.merge) parts.push_back(readSweepPart(d));
    whole = mergeSweepParts(parts, o.merge);
    whole.manifest["command"] = quoteCommand(o);
    prepareReportDir(o.out);
  } catch (const InputError& e) {
    std::cerr << "cairn sweep: " << e.what() << "\n";
    return 2;
  }
  try {
    whole.manifest.erase("replay");
    for (const std::string& d : o.merge) {
      std::error_code ec;
      if (!fs::exists(fs::path(d) / "replay.html", ec)) continue;
      fs::copy_file(fs::path(d) / "replay.html", fs::path(o.out) / "replay.html", fs::copy_options::overwrite_existing, ec);
      if (ec) throw InputError((fs::path(o.out) / "replay.html").string(), "", "cannot copy the replay page: " + ec.message());
      whole.manifest["replay"] = "replay.html";
      break;
    }
    writeSweepFiles(o.out, whole);
  } catch (const InputError& e) {
    std::cerr << "cairn sweep: " << e.what() << "\n";
    return 2;
  }
  drawPlot(o.out);
  std::cout << "merged " << o.merge.size() << " parts, " << whole.rows.size() << " jobs: "
            << (fs::path(o.out) / "sweep.md").string() << "\n";
  return 0;
}

int sweep(const SweepOptions& o) {
  SceneArg in;
  SweepPlan plan;
  Shard shard;
  Measure axis = Measure::JointError;
  int exact_every = 0;
  try {
    if (o.scene.empty()) throw InputError("SCENE", "", "missing: give a scene file or standard key, or --merge DIR...");
    in = resolveSceneArg(o.scene);
    if (o.steps) {
      if (*o.steps < 1) throw InputError("--steps", "", "must be >= 1 (got " + std::to_string(*o.steps) + ")");
      in.scene.steps = *o.steps;
    }
    std::vector<VaryAxis> axes;
    for (const std::string& v : o.vary) axes.push_back(parseVary(v, in.scene));
    plan = makeSweepPlan(axes, in.scene);
    if (o.shard) shard = parseShard(*o.shard);
    if (o.exact_every && *o.exact_every < 0)
      throw InputError("--exact-every", "", "must be >= 0 (0: never; got " + std::to_string(*o.exact_every) + ")");
    // Ten samples per run by default: enough to see the trend, cheap next
    // to the run for the few hundred rows the exact solver is meant for.
    exact_every = o.exact_every ? *o.exact_every : std::max(1, in.scene.steps / 10);
    const ValidationSpec spec = validationSpec(in.scene);
    axis = defaultParetoAxis(in.scene, spec);
    if (o.pareto_axis) {
      const auto m = measureByColumn(*o.pareto_axis);
      if (!m || *m == Measure::MsPerStep)
        throw InputError("--pareto-axis", "", "'" + *o.pareto_axis + "' is not an error column (" + errorColumns() + ")");
      axis = *m;
    }
    prepareReportDir(o.out);
  } catch (const InputError& e) {
    std::cerr << "cairn sweep: " << e.what() << "\n";
    return 2;
  }

  SweepRunner runner(in.scene, plan, exact_every);
  SweepTable table;
  Json& m = table.manifest;
  m["format"] = "cairn sweep 1";
  m["scene"] = in.name;
  m["source"] = in.source;
  m["scene_hash"] = fingerprint(sceneToText(in.scene));
  m["kind"] = kindName(runner.spec().kind);
  m["steps"] = in.scene.steps;
  m["dt"] = in.scene.dt;
  Json vary = Json::array();
  for (const VaryAxis& a : plan.axes) vary.push_back(Json{{"key", a.key}, {"values", a.values}});
  m["vary"] = vary;
  m["columns"] = plan.columns;
  m["jobs"] = plan.jobs.size();
  m["cairn_jobs"] = plan.cairn_jobs;
  m["pareto_axis"] = measureColumn(axis);
  m["analytic"] = runner.analyticName();
  m["exact_every"] = exact_every;
  if (!shard.whole()) m["shard"] = *o.shard;
  m["command"] = quoteCommand(o);
  table.setting_columns = plan.columns;

  int mine = 0;
  for (const SweepJob& job : plan.jobs) mine += shard.owns(job.index);
  std::cout << "sweeping " << in.name << ": " << plan.jobs.size() << " jobs (" << plan.cairn_jobs << " cairn, "
            << plan.jobs.size() - size_t(plan.cairn_jobs) << " Bullet)";
  if (!shard.whole()) std::cout << ", shard " << *o.shard << " runs " << mine;
  std::cout << ", " << in.scene.steps << " steps each\n" << std::flush;
  for (const SweepJob& job : plan.jobs) {
    if (!shard.owns(job.index)) continue;
    table.rows.push_back(runner.run(job));
    const SweepRow& r = table.rows.back();
    std::cout << "  job " << job.index << ":";
    for (size_t c = 0; c < plan.columns.size(); ++c) std::cout << " " << plan.columns[c] << "=" << job.settings[c];
    if (r[Measure::MsPerStep]) std::cout << "  " << *r[Measure::MsPerStep] << " ms/step";
    if (r[axis]) std::cout << ", " << measureColumn(axis) << " " << *r[axis];
    if (r.status != "ok") std::cout << " (" << r.status << ")";
    std::cout << "\n" << std::flush;
  }
  markPareto(table.rows, axis);
  try {
    if (shard.owns(0)) {  // the scene as given, cairn and Bullet, for the viewer
      std::cout << "recording the replay (the scene's own settings, cairn and Bullet)...\n" << std::flush;
      const SceneResult r = validateScene(in.scene, in.name, in.source, in.description, true);
      writeReplayPage((fs::path(o.out) / "replay.html").string(), *r.replay);
      m["replay"] = "replay.html";
    }
    writeSweepFiles(o.out, table);
  } catch (const InputError& e) {
    std::cerr << "cairn sweep: " << e.what() << "\n";
    return 2;
  }
  if (shard.whole()) drawPlot(o.out);
  else std::cout << "part " << *o.shard << " written; join the parts with cairn sweep --merge DIR... --out DIR\n";
  std::cout << "sweep: " << (fs::path(o.out) / "sweep.md").string() << "\n";
  return 0;
}

}  // namespace

void addSweepCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<SweepOptions>();
  CLI::App* cmd = app.add_subcommand("sweep", "Run a scene over a grid of solver settings: speed against accuracy");
  cmd->add_option("scene", opt->scene, "Scene file or standard scenario key (cairn scenes --list)");
  cmd->add_option("--vary", opt->vary, "KEY=V1,V2,... (method, substeps, iterations, erp, dt, ...); repeat for a grid")
      ->allow_extra_args(false);
  cmd->add_option("--out", opt->out, "Output directory (default: sweep)");
  cmd->add_option("--shard", opt->shard, "Run only part i of n (0-based: 0/3, 1/3, 2/3); join with --merge");
  cmd->add_option("--steps", opt->steps, "Number of steps (overrides the scene's)");
  cmd->add_option("--exact-every", opt->exact_every, "Exact-LCP distance every K-th step (0: never; default steps/10)");
  cmd->add_option("--pareto-axis", opt->pareto_axis, "Error column of the Pareto front (default by scene kind)");
  cmd->add_option("--merge", opt->merge, "Join the parts in these directories into --out")->allow_extra_args(true);
  cmd->callback([opt, &status] { status = opt->merge.empty() ? sweep(*opt) : merge(*opt); });
}

}  // namespace cairn::cli
