// SceneDesc -> JSON: the inverse of world/scene_json.cpp's reader, so a
// scene built in code (validation/scenarios.hpp) can be shipped as a file
// and read back by loadScene() to the same bodies, joints and settings.
//
// Every solver setting is written (a file says which settings it ran
// with); body and joint fields are written when they differ from their
// defaults, which the reader fills back in. Numbers are written as the
// shortest text that reads back to the same double, so the round trip is
// exact. Values JSON cannot spell (infinite break forces, an infinite
// angular-velocity cap) are the defaults and are left out.
//
// Limits of the round trip: a convex hull is written as its vertices (the
// reader rebuilds the same hull from them); a mesh is written as the OBJ
// path it was loaded from (ShapeDesc::source), which must still exist.
#pragma once

#include "cairn/scene.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace cairn::validation {

// The scene as a JSON object; `description` (units, what a user should
// see) goes first when non-empty, the raw validation block last.
nlohmann::ordered_json sceneToJson(const SceneDesc& scene, const std::string& description = "");

// The same as text laid out for reading: one body, spring or joint per
// line, ending with a newline.
std::string sceneToText(const SceneDesc& scene, const std::string& description = "");

// Writes sceneToText to `path` (through a temporary file and a rename).
// Throws InputError naming the path when it cannot be written.
void writeScene(const std::string& path, const SceneDesc& scene, const std::string& description = "");

}  // namespace cairn::validation
