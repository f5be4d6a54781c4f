// `cairn bench [SCENE...] [--repeat N] [--steps N] [--threads N]
//  [--set KEY=VALUE]... [--cairn-set KEY=VALUE]... [--bullet-set KEY=VALUE]...
//  [--out DIR]`
// `cairn bench --scaling [...]`
//
// Runs each scene (a scene file or a standard scenario key; by default
// pyramid-20, pile-1000, chain-100, ragdoll, column-20, mass-ratio-100 and
// pyramid-100 for 200 steps) in cairn and in Bullet 3.24 with its defaults and matched to
// cairn, in one process, taking turns repeat by repeat, and prints and
// writes DIR/bench.csv, bench.md, bench.json and plots: time per step,
// Bullet / cairn ratios, cairn's rows, contacts and stage times, and each
// run's accuracy beside its time (validation/bench_*.hpp,
// docs/benchmarks.md). --scaling runs the scaling series instead
// (pyramids, piles and chains of growing size) and adds one log-log plot
// per family.
//
// Exit status: 0 written; 2 bad input (an unknown scene, a count below 1,
// a bad override, an unwritable DIR), with one line on stderr naming it
// and nothing written; 3 a cairn run stopped on a non-finite state (the
// files are written, the row says where).
#include "cli/commands.hpp"
#include "cli/scene_arg.hpp"
#include "cairn/error.hpp"
#include "validation/bench_plan.hpp"
#include "validation/bench_table.hpp"
#include "validation/machine.hpp"
#include "validation/plot_script.hpp"
#include "validation/report.hpp"

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

namespace cairn::cli {

namespace {

namespace fs = std::filesystem;
using namespace validation;

struct BenchOptions {
  std::vector<std::string> scenes;
  int repeat = 3;
  std::string out = "bench";
  bool scaling = false;
  BenchOverrides overrides;
};

std::string quoteCommand(const BenchOptions& o) {
  std::string cmd = "cairn bench";
  for (const auto& s : o.scenes) cmd += " " + s;
  if (o.scaling) cmd += " --scaling";
  cmd += " --repeat " + std::to_string(o.repeat);
  if (o.overrides.steps) cmd += " --steps " + std::to_string(*o.overrides.steps);
  if (o.overrides.threads != 1) cmd += " --threads " + std::to_string(o.overrides.threads);
  for (const auto& s : o.overrides.all) cmd += " --set " + s;
  for (const auto& s : o.overrides.cairn) cmd += " --cairn-set " + s;
  for (const auto& s : o.overrides.bullet) cmd += " --bullet-set " + s;
  return cmd + " --out " + o.out;
}

// The scenes to run: the scaling series, the given ones, or the default list.
std::vector<BenchScene> plan(const BenchOptions& o) {
  checkBenchCounts(o.overrides, o.repeat);
  if (o.scaling && !o.scenes.empty())
    throw InputError("--scaling", "", "runs its own series of pyramids, piles and chains: give no SCENE with it");
  std::vector<ListedScene> wanted = o.scaling ? scalingSeries() : defaultBenchScenes();
  if (!o.scaling && !o.scenes.empty()) {
    wanted.clear();
    for (const std::string& s : o.scenes) wanted.push_back({s, 0});
  }
  std::vector<BenchScene> scenes;
  for (const ListedScene& w : wanted) {
    SceneArg in = resolveSceneArg(w.key);
    if (w.steps > 0) in.scene.steps = w.steps;
    scenes.push_back(makeBenchScene(in.name, in.scene, o.overrides));
  }
  return scenes;
}

int bench(const BenchOptions& o) {
  BenchTable table;
  try {
    table.scenes = plan(o);
    prepareReportDir(o.out);
  } catch (const InputError& e) {
    std::cerr << "cairn bench: " << e.what() << "\n";
    return 2;
  }
  using Json = nlohmann::ordered_json;
  const MachineInfo machine = currentMachine();
  Json& m = table.manifest;
  m["format"] = "cairn bench 1";
  m["command"] = quoteCommand(o);
  m["date"] = utcNow();
  // Whether the logical CPUs a run on several threads uses were cores of
  // their own, at the start and at the end (validation/machine.hpp).
  const int probe_threads = std::min(std::max(2, o.overrides.threads), std::max(machine.cpus, 1));
  m["machine"] = Json{{"cpus", machine.cpus},
                      {"cpu_model", machine.cpu_model},
                      {"load_start", loadAverage()},
                      {"core_check_threads", probe_threads},
                      {"core_share_start", coreShare(probe_threads)}};
  m["repeats"] = o.repeat;
  m["threads"] = o.overrides.threads;
  if (o.overrides.steps) m["steps"] = *o.overrides.steps;
  m["set"] = o.overrides.all;
  m["cairn_set"] = o.overrides.cairn;
  m["bullet_set"] = o.overrides.bullet;
  m["scaling"] = o.scaling;
  Json names = Json::array();
  for (const BenchScene& s : table.scenes) names.push_back(s.name);
  m["scenes"] = names;

  bool stopped = false;
  for (const BenchScene& s : table.scenes) {
    std::cout << "benching " << s.name << ": " << s.base.bodies.size() << " bodies, " << s.base.joints.size()
              << " joints, " << s.base.steps << " steps, " << o.repeat << " repeats of cairn and Bullet (defaults, matched)\n"
              << std::flush;
    table.results.push_back(runBenchScene(s, o.repeat, [](const std::string& line) {
      std::cout << "  " << line << "\n" << std::flush;
    }));
    stopped = stopped || table.results.back()[BenchEngine::Cairn].status.rfind("stopped", 0) == 0;
  }
  m["machine"]["load_end"] = loadAverage();
  m["machine"]["core_share_end"] = coreShare(probe_threads);

  try {
    writeBenchFiles(o.out, table);
  } catch (const InputError& e) {
    std::cerr << "cairn bench: " << e.what() << "\n";
    return 2;
  }
  const std::string script = findPlotScript("plot_bench.py");
  const std::string warning = script.empty() ? "validation/plot_bench.py not found; plots not drawn"
                                             : runPlotScript("/usr/bin/python3", script, o.out);
  if (!warning.empty()) std::cerr << "cairn bench: warning: " << warning << "\n";
  std::cout << "\n" << benchMarkdown(table) << "\nbench: " << (fs::path(o.out) / "bench.md").string() << "\n";
  return stopped ? 3 : 0;
}

}  // namespace

void addBenchCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand("bench", "Time cairn against Bullet (its defaults and matched), accuracy beside");
  cmd->add_option("scene", opt->scenes, "Scene files or standard scenario keys (default: the benchmark list)");
  cmd->add_flag("--scaling", opt->scaling, "Run the scaling series (pyramids, piles, chains of growing size)");
  cmd->add_option("--repeat", opt->repeat, "Runs per engine configuration; the median is reported (default 3)");
  cmd->add_option("--steps", opt->overrides.steps, "Steps per run (overrides every scene's)");
  cmd->add_option("--threads", opt->overrides.threads, "cairn's SolverSettings::threads (default 1)");
  cmd->add_option("--set", opt->overrides.all, "KEY=VALUE for every engine (iterations, substeps, dt, ...); repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--cairn-set", opt->overrides.cairn, "KEY=VALUE for cairn only (e.g. iterations=4); repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--bullet-set", opt->overrides.bullet, "KEY=VALUE for both Bullet configurations; repeatable")
      ->allow_extra_args(false);
  cmd->add_option("--out", opt->out, "Output directory (default: bench)");
  cmd->callback([opt, &status] { status = bench(*opt); });
}

}  // namespace cairn::cli
