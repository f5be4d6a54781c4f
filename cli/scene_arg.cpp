#include "cli/scene_arg.hpp"

#include "cairn/error.hpp"
#include "validation/compare.hpp"
#include "validation/standard_scenes.hpp"
#include "world/scene_json.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace cairn::cli {

namespace fs = std::filesystem;

namespace {

std::string readDescription(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  const auto j = nlohmann::json::parse(ss.str(), nullptr, false);
  if (j.is_object() && j.contains("description") && j["description"].is_string()) return j["description"].get<std::string>();
  return "";
}

}  // namespace

SceneArg resolveSceneArg(const std::string& arg) {
  SceneArg in;
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

}  // namespace cairn::cli
