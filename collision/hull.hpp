// Convex hulls from point clouds (qhull, Debian's libqhull-dev).
#pragma once

#include "cairn/limits.hpp"
#include "cairn/shape.hpp"

#include <memory>
#include <string>
#include <vector>

namespace cairn {

// Builds the hull of `points`. Throws InputError(object, field, ...) when a
// point is not finite, there are more than limits.hull_points, or the points
// are degenerate (fewer than 4, or all coplanar): a hull must enclose volume.
std::shared_ptr<const ConvexHullData> buildConvexHull(const std::vector<Vec3>& points,
                                                      const std::string& object = "",
                                                      const std::string& field = "points",
                                                      const InputLimits& limits = {});

}  // namespace cairn
