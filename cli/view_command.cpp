// `cairn view SCENE [RUN.csv] [--run] [--out replay.html] [--steps N]
//  [--method M] [--substeps N] [--iterations N]`: write one self-contained
// HTML page that replays a run in 3D (docs/viewer.md).
//
// SCENE is a scene file or a standard scenario key. With RUN.csv (what
// `cairn run --out` writes) the page replays that trajectory; the overlays
// that only a running World shows (contacts, joints, sleep, islands) are
// then absent and the page says so. With --run, or with neither --run nor
// RUN.csv, the scene is run here first and everything is recorded. Giving
// both is an error: a replay shows one run.
//
// Exit status: 0 written (its size is printed); 2 bad input (a missing or
// bad scene, a CSV that does not match the scene, an empty run, both RUN.csv
// and --run, an unwritable output), with one line on stderr naming the file
// and what is wrong, and nothing written; 3 a non-finite state during --run
// (nothing written).
#include "cli/commands.hpp"
#include "cli/scene_arg.hpp"
#include "cli/solver_overrides.hpp"
#include "cairn/error.hpp"
#include "validation/replay_csv.hpp"
#include "validation/replay_page.hpp"
#include "validation/replay_record.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

namespace cairn::cli {

namespace {

namespace fs = std::filesystem;
using validation::Replay;

struct ViewOptions {
  std::string scene;
  std::string csv;
  bool run = false;
  std::string out = "replay.html";
  std::optional<int> steps;
  SolverOverrides solver;
};

std::string readFile(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, "", "no such file");
  if (fs::is_directory(path, ec)) throw InputError(path, "", "is a directory, not a trajectory CSV");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path, "", "cannot be read");
  std::stringstream s;
  s << f.rdbuf();  // an empty file sets failbit here; readRunCsv names it
  return s.str();
}

std::string megabytes(std::size_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f MB", double(bytes) / 1e6);
  return buf;
}

int view(const ViewOptions& opt) {
  SceneArg in;
  Replay replay;
  std::string csv_text;
  try {
    in = resolveSceneArg(opt.scene);
    const bool from_csv = !opt.csv.empty();
    if (from_csv && opt.run)
      throw InputError(opt.csv, "", "given with --run: a replay shows one run; drop --run to replay the CSV, or the CSV to run the scene");
    if (from_csv && (opt.steps || opt.solver.method || opt.solver.substeps || opt.solver.iterations))
      throw InputError(opt.csv, "", "--steps and solver options apply to --run only; the CSV is replayed as recorded");
    if (opt.steps) {
      if (*opt.steps < 1) throw InputError("--steps", "", "must be >= 1 (got " + std::to_string(*opt.steps) + ")");
      in.scene.steps = *opt.steps;
    }
    applySolverOverrides(opt.solver, in.scene);
    const fs::path dir = fs::path(opt.out).parent_path();
    std::error_code ec;
    if (!dir.empty() && !fs::is_directory(dir, ec)) throw InputError(opt.out, "", "its directory does not exist");
    if (from_csv) {
      csv_text = readFile(opt.csv);
      replay = validation::describeScene(in.scene);
      validation::readRunCsv(csv_text, opt.csv, replay);
      replay.source = opt.csv + " (trajectory of " + in.source + ")";
      replay.notes.push_back("Replayed from a trajectory CSV: contacts, joints, sleep and islands are recorded only "
                             "while cairn runs the scene (cairn view SCENE --run).");
    } else if (in.scene.steps < 1) {
      throw InputError(in.source, "steps", "is 0: an empty run has nothing to replay (pass --steps N)");
    }
  } catch (const InputError& e) {
    std::cerr << "cairn view: " << e.what() << "\n";
    return 2;
  }

  if (opt.csv.empty()) {
    if (!opt.run) std::cout << "no RUN.csv given: running " << in.name << " (as --run)\n";
    std::cout << "running " << in.name << ": " << in.scene.bodies.size() << " bodies, " << in.scene.steps
              << " steps...\n" << std::flush;
    const std::string failure = validation::recordRun(in.scene, replay);
    if (!failure.empty()) {
      std::cerr << "cairn view: " << in.source << ": " << failure << "; nothing written\n";
      return 3;
    }
    validation::fitContacts(replay);
    replay.source = in.source + ", run by cairn view";
  }
  replay.title = in.name;
  try {
    const std::size_t bytes = validation::writeReplayPage(opt.out, replay);
    std::cout << "wrote " << opt.out << ": " << megabytes(bytes) << " (" << bytes << " bytes), "
              << replay.bodyCount() << " bodies, " << replay.shapeCount() << " shapes, " << replay.cairn.frames()
              << " frames\n";
  } catch (const InputError& e) {
    std::cerr << "cairn view: " << e.what() << "\n";
    return 2;
  }
  return 0;
}

}  // namespace

void addViewCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand("view", "Write an HTML page that replays a run in 3D (docs/viewer.md)");
  cmd->add_option("scene", opt->scene, "Scene file or standard scenario key")->required();
  cmd->add_option("run_csv", opt->csv, "Trajectory CSV written by cairn run --out (default: run the scene)");
  cmd->add_flag("--run", opt->run, "Run the scene and record contacts, joints, sleep and islands too");
  cmd->add_option("--out", opt->out, "The page to write (default: replay.html)");
  cmd->add_option("--steps", opt->steps, "Number of steps for --run (overrides the scene's)");
  addSolverOverrideOptions(*cmd, opt->solver);
  cmd->callback([opt, &status] { status = view(*opt); });
}

}  // namespace cairn::cli
