// `cairn validate SCENE... [--against bullet] [--report DIR] [--steps N]`:
// run each scene in cairn and in Bullet with matched settings and compare
// them (validation/compare.hpp), with closed forms where they exist.
//
// SCENE is a scene file or a standard scenario key (`cairn scenes --list`).
// Prints a summary table (scene, key figures cairn / Bullet, ms/step,
// pass or fail) and one line per figure outside its tolerance; with
// --report, writes DIR/report.md, a CSV per scene and PNG plots.
//
// Exit status: 0 every scene within its tolerances; 1 some figure outside
// them; 2 bad input (a missing scene file, a bad scene or validation block,
// an unwritable report directory), with one line on stderr naming it.
#include "cli/commands.hpp"
#include "dynamics/error.hpp"
#include "validation/compare.hpp"
#include "validation/report.hpp"
#include "validation/standard_scenes.hpp"
#include "world/scene_json.hpp"

#include <nlohmann/json.hpp>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <unistd.h>

namespace cairn::cli {

namespace {

namespace fs = std::filesystem;
using validation::SceneResult;

struct ValidateOptions {
  std::vector<std::string> scenes;
  std::string against = "bullet";
  std::string report;
  std::optional<int> steps;
};

struct Input {
  SceneDesc scene;
  std::string name, source, description;
};

std::string readDescription(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  const auto j = nlohmann::json::parse(ss.str(), nullptr, false);
  if (j.is_object() && j.contains("description") && j["description"].is_string()) return j["description"].get<std::string>();
  return "";
}

// A scene file if one exists at `arg`, else a standard scenario key.
Input resolve(const std::string& arg) {
  Input in;
  std::error_code ec;
  const bool looks_like_path = arg.find('/') != std::string::npos || fs::path(arg).extension() == ".json";
  if (fs::exists(arg, ec)) {
    if (fs::is_directory(arg, ec)) throw InputError(arg, "", "is a directory, not a scene file");
    in.scene = loadScene(arg);
    in.name = fs::path(arg).stem().string();
    in.source = arg;
    in.description = readDescription(arg);
  } else if (looks_like_path) {
    throw InputError(arg, "", "no such scene file");
  } else {
    try {
      validation::StandardScene s = validation::standardScene(arg);
      in.scene = std::move(s.scene);
      in.description = std::move(s.description);
    } catch (const InputError&) {
      throw InputError(arg, "", "no such scene file or standard scenario (`cairn scenes --list` lists them)");
    }
    in.name = arg;
    in.source = "standard scenario " + arg + " (validation/standard_scenes.cpp)";
  }
  // The validation block is checked now, before anything runs.
  try {
    (void)validation::validationSpec(in.scene);
  } catch (const InputError& e) {
    throw InputError(in.source == arg ? arg + ": " + e.object() : e.object(), e.field(), e.message());
  }
  return in;
}

// validation/plot_report.py: $CAIRN_PLOT_SCRIPT, else next to the source
// tree the executable was built in (build*/cairn -> ../validation), else
// under the working directory.
std::string findPlotScript() {
  if (const char* env = std::getenv("CAIRN_PLOT_SCRIPT")) return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::vector<fs::path> candidates;
  if (!ec)
    for (fs::path d = exe.parent_path(); !d.empty() && d != d.root_path(); d = d.parent_path())
      candidates.push_back(d / "validation" / "plot_report.py");
  candidates.push_back(fs::current_path(ec) / "validation" / "plot_report.py");
  for (const auto& c : candidates)
    if (fs::exists(c, ec)) return c.string();
  return "";
}

std::string utcNow() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &tm);
  return buf;
}

std::string commandLine(const ValidateOptions& opt) {
  std::string cmd = "cairn validate";
  for (const auto& s : opt.scenes) cmd += " " + s;
  if (opt.steps) cmd += " --steps " + std::to_string(*opt.steps);
  if (!opt.report.empty()) cmd += " --report " + opt.report;
  return cmd;
}

int validate(const ValidateOptions& opt) {
  std::vector<Input> inputs;
  try {
    if (opt.against != "bullet") throw InputError("--against", "", "only 'bullet' is available");
    if (opt.steps && *opt.steps < 1) throw InputError("--steps", "", "must be >= 1");
    for (const auto& s : opt.scenes) {
      inputs.push_back(resolve(s));
      if (opt.steps) inputs.back().scene.steps = *opt.steps;
    }
    if (!opt.report.empty()) validation::prepareReportDir(opt.report);
  } catch (const InputError& e) {
    std::cerr << "cairn validate: " << e.what() << "\n";
    return 2;
  }

  std::vector<SceneResult> results;
  for (const Input& in : inputs) {
    std::cout << "validating " << in.name << ": " << in.scene.bodies.size() << " bodies, " << in.scene.joints.size()
              << " joints, " << in.scene.steps << " steps, cairn and Bullet...\n"
              << std::flush;
    try {
      results.push_back(validation::validateScene(in.scene, in.name, in.source, in.description));
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
    info.date = utcNow();
    info.plot_script = findPlotScript();
    try {
      const std::string warning = validation::writeReport(opt.report, results, info);
      if (!warning.empty()) std::cerr << "cairn validate: warning: " << warning << "\n";
    } catch (const InputError& e) {
      std::cerr << "cairn validate: " << e.what() << "\n";
      return 2;
    }
    std::cout << "report: " << (fs::path(opt.report) / "report.md").string() << "\n";
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
  cmd->callback([opt, &status] { status = validate(*opt); });
}

}  // namespace cairn::cli
