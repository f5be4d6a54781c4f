// `cairn scenes --out DIR`: write every standard scenario
// (validation/standard_scenes.hpp) as a scene file DIR/KEY.json, with its
// description and validation block. scenes/ in the repository is this
// command's output. `cairn scenes --list` prints the keys.
// Exit status 2 when DIR cannot be created or written.
#include "cli/commands.hpp"
#include "cairn/error.hpp"
#include "validation/scene_writer.hpp"
#include "validation/standard_scenes.hpp"

#include <filesystem>
#include <iostream>
#include <memory>

namespace cairn::cli {

namespace {

struct ScenesOptions {
  std::string out;
  bool list = false;
};

int writeScenes(const ScenesOptions& opt) {
  if (opt.list) {
    for (const auto& key : validation::standardSceneNames()) std::cout << key << "\n";
    if (opt.out.empty()) return 0;
  }
  if (opt.out.empty()) {
    std::cerr << "cairn scenes: give --out DIR (or --list)\n";
    return 2;
  }
  try {
    std::error_code ec;
    std::filesystem::create_directories(opt.out, ec);
    if (ec || !std::filesystem::is_directory(opt.out)) throw InputError(opt.out, "", "cannot create output directory");
    int n = 0;
    for (const auto& key : validation::standardSceneNames()) {
      const validation::StandardScene s = validation::standardScene(key);
      validation::writeScene((std::filesystem::path(opt.out) / (key + ".json")).string(), s.scene, s.description);
      ++n;
    }
    std::cout << "wrote " << n << " scenes to " << opt.out << "\n";
  } catch (const InputError& e) {
    std::cerr << "cairn scenes: " << e.what() << "\n";
    return 2;
  }
  return 0;
}

}  // namespace

void addScenesCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<ScenesOptions>();
  CLI::App* cmd = app.add_subcommand("scenes", "Write the standard scenarios as scene files");
  cmd->add_option("--out", opt->out, "Directory to write KEY.json files into");
  cmd->add_flag("--list", opt->list, "Print the standard scenario keys");
  cmd->callback([opt, &status] { status = writeScenes(*opt); });
}

}  // namespace cairn::cli
