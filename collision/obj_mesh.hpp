// Wavefront OBJ loading for static triangle meshes (level geometry).
#pragma once

#include "cairn/shape.hpp"

#include <memory>
#include <string>

namespace cairn {

// Reads `v` and `f` records (faces with more than 3 vertices are fanned into
// triangles; texture and normal indices are ignored; negative indices count
// from the end as the format says). Throws InputError naming the file and
// the line on anything unreadable or malformed, or a non-finite vertex.
std::shared_ptr<const TriangleMeshData> loadObjMesh(const std::string& path,
                                                    const std::string& object = "",
                                                    const std::string& field = "obj");

}  // namespace cairn
