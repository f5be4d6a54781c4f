// TEMPORARY until the collision module lands (being written now).
#include "collision/hull.hpp"
#include "dynamics/error.hpp"
namespace cairn {
std::shared_ptr<const ConvexHullData> buildConvexHull(const std::vector<Vec3>&, const std::string& object,
                                                      const std::string& field) {
  throw InputError(object, field, "convex hulls are not built yet");
}
}  // namespace cairn
