// Wavefront OBJ loading for static triangle meshes (level geometry).
#pragma once

#include "cairn/limits.hpp"
#include "cairn/shape.hpp"

#include <istream>
#include <memory>
#include <string>

namespace cairn {

// Reads `v` and `f` records (faces with more than 3 vertices are fanned into
// triangles; texture and normal indices are ignored; negative indices count
// from the end as the format says; triangles without area are dropped).
// Throws InputError naming the file and the line on anything unreadable or
// malformed, a vertex that is not finite or beyond kMaxMagnitude, a count
// beyond `limits`, or a mesh with no triangle that has an area.
std::shared_ptr<const TriangleMeshData> loadObjMesh(const std::string& path,
                                                    const std::string& object = "",
                                                    const std::string& field = "obj",
                                                    const InputLimits& limits = {});

// The same from a stream; `path` is only used in messages.
std::shared_ptr<const TriangleMeshData> parseObjMesh(std::istream& in, const std::string& path,
                                                     const std::string& object = "",
                                                     const std::string& field = "obj",
                                                     const InputLimits& limits = {});

}  // namespace cairn
