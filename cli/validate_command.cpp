// `cairn validate SCENE... [--against bullet] [--report DIR] [--steps N]
//  [--method auto|pgs|direct|lcp] [--substeps N] [--iterations N]`:
// run each scene in cairn and in Bullet with matched settings and compare
// them (validation/compare.hpp), with closed forms where they exist.
//
// SCENE is a scene file or a standard scenario key (`cairn scenes --list`).
// Prints a summary table (scene, key figures cairn / Bullet, ms/step,
// pass or fail) and one line per figure outside its tolerance; with
// --report, writes DIR/report.md, a CSV per scene, PNG plots and a replay
// page per scene (DIR/SCENE.replay.html: cairn and Bullet in 3D).
//
// Exit status: 0 every scene within its tolerances; 1 some figure outside
// them; 2 bad input (a missing scene file, a bad scene or validation block,
// an unwritable report directory), with one line on stderr naming it.
#include "cli/commands.hpp"
#include "cli/scene_arg.hpp"
#include "cli/solver_overrides.hpp"
#include "cairn/error.hpp"
#include "validation/compare.hpp"
#include "validation/machine.hpp"
#include "validation/plot_script.hpp"
#include "validation/report.hpp"

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace cairn::cli {

namespace {

namespace fs = std::filesystem;
using validation::SceneResult;

struct ValidateOptions {
  std::vector<std::string> scenes;
  std::string against = "bullet";
  std::string report;
  std::optional<int> steps;
  SolverOverrides solver;
};

std::string commandLine(const ValidateOptions& opt) {
  std::string cmd = "cairn validate";
  for (const auto& s : opt.scenes) cmd += " " + s;
  if (opt.steps) cmd += " --steps " + std::to_string(*opt.steps);
  cmd += solverOverridesText(opt.solver);
  if (!opt.report.empty()) cmd += " --report " + opt.report;
  return cmd;
}

int validate(const ValidateOptions& opt) {
  std::vector<SceneArg> inputs;
  try {
    if (opt.against != "bullet") throw InputError("--against", "", "only 'bullet' is available");
    if (opt.steps && *opt.steps < 1) throw InputError("--steps", "", "must be >= 1");
    for (const auto& s : opt.scenes) {
      inputs.push_back(resolveSceneArg(s));
      if (opt.steps) inputs.back().scene.steps = *opt.steps;
      applySolverOverrides(opt.solver, inputs.back().scene);
    }
    if (!opt.report.empty()) validation::prepareReportDir(opt.report);
  } catch (const InputError& e) {
    std::cerr << "cairn validate: " << e.what() << "\n";
    return 2;
  }

  std::vector<SceneResult> results;
  for (const SceneArg& in : inputs) {
    std::cout << "validating " << in.name << ": " << in.scene.bodies.size() << " bodies, " << in.scene.joints.size()
              << " joints, " << in.scene.steps << " steps, cairn and Bullet...\n"
              << std::flush;
    try {
      results.push_back(validation::validateScene(in.scene, in.name, in.source, in.description, !opt.report.empty()));
    } catch (const InputError& e) {
      std::cerr << "cairn validate: " << in.source << ": " << e.what() << "\n";
      return 2;
    }
  }

  std::cout << "\n" << validation::summaryTable(results);
  bool all_pass = true;
  for (const SceneResult& r : results) {
    for (const auto& line : validation::failureLines(r)) std::cout << "outside tolerance: " << line << "\n";
    all_pass = all_pass && r.pass();
  }
  if (!opt.report.empty()) {
    validation::ReportInfo info;
    info.command = commandLine(opt);
    info.date = validation::utcNow();
    info.plot_script = validation::findPlotScript("plot_report.py");
    try {
      const std::string warning = validation::writeReport(opt.report, results, info);
      if (!warning.empty()) std::cerr << "cairn validate: warning: " << warning << "\n";
    } catch (const InputError& e) {
      std::cerr << "cairn validate: " << e.what() << "\n";
      return 2;
    }
    std::cout << "report: " << (fs::path(opt.report) / "report.md").string() << "\n";
    std::cout << "replays (open in a browser): " << (fs::path(opt.report) / "*.replay.html").string() << "\n";
  }
  return all_pass ? 0 : 1;
}

}  // namespace

void addValidateCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<ValidateOptions>();
  CLI::App* cmd = app.add_subcommand("validate", "Compare cairn with Bullet (and closed forms) on scenes");
  cmd->add_option("scene", opt->scenes, "Scene files or standard scenario keys (cairn scenes --list)")->required();
  cmd->add_option("--against", opt->against, "Reference engine (only 'bullet')");
  cmd->add_option("--report", opt->report, "Directory for report.md, CSVs and PNG plots");
  cmd->add_option("--steps", opt->steps, "Number of steps (overrides each scene's)");
  addSolverOverrideOptions(*cmd, opt->solver);
  cmd->callback([opt, &status] { status = validate(*opt); });
}

}  // namespace cairn::cli
