// The JSON scene format (docs/scene-format.md) to and from SceneDesc.
#pragma once

#include "cairn/limits.hpp"
#include "cairn/scene.hpp"

#include <string>

namespace cairn {

// Reads and validates a scene file. Throws InputError whose message starts
// with the file name and names the object and field at fault; nothing else
// escapes for any content of the file. `limits` bound what is allocated
// (include/cairn/limits.hpp); values outside the ranges a step can carry are
// refused (world/def_checks.hpp).
SceneDesc loadScene(const std::string& path, const InputLimits& limits = {});

// Parses scene JSON text; `path` is used for messages and to resolve
// relative paths (meshes).
SceneDesc parseScene(const std::string& text, const std::string& path, const InputLimits& limits = {});

// Checks cross-references and values of a whole scene (the same checks the
// World does on creation) without building anything.
void validateScene(const SceneDesc& scene);

}  // namespace cairn
