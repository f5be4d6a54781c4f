// TEMPORARY until the collision module lands (being written now).
#include "collision/obj_mesh.hpp"
#include "dynamics/error.hpp"
namespace cairn {
std::shared_ptr<const TriangleMeshData> loadObjMesh(const std::string& path, const std::string& object,
                                                    const std::string& field) {
  throw InputError(object, field, "meshes are not loaded yet: " + path);
}
}  // namespace cairn
