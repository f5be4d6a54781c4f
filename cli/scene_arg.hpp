// A SCENE argument of `cairn validate` and `cairn sweep`: a scene file, or
// a standard scenario key (`cairn scenes --list`). An argument with a
// slash or a .json ending that does not exist is a missing file, not a key.
#pragma once

#include "cairn/scene.hpp"

#include <string>

namespace cairn::cli {

struct SceneArg {
  SceneDesc scene;
  std::string name;         // file stem or scenario key
  std::string source;       // the path, or "standard scenario KEY (...)"
  std::string description;  // the file's "description", or the scenario's
};

// Loads the scene and checks its validation block now, before anything
// runs. Throws InputError naming the argument.
SceneArg resolveSceneArg(const std::string& arg);

}  // namespace cairn::cli
