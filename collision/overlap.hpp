// Overlap tests: does a convex query shape (sphere, box, capsule, cylinder,
// convex hull) at a pose intersect a shape at a pose? Closed solids: shapes
// that touch overlap.
//
//   convex  GJK distance between the cores (gjk.hpp) <= r_A + r_B, the sum
//           of the rounding radii (exact for polytope cores, to GJK's
//           relative accuracy 1e-13 for a cylinder; stops early once the
//           lower bound exceeds the radii).
//   plane   the query's deepest point along -n is at or below the plane:
//           n . s(-n) <= e.
//   mesh    any triangle whose box meets the query's box (through the BVH)
//           within distance 0 by the same GJK test on the triangle.
#pragma once

#include "cairn/shape.hpp"

namespace cairn {

// False when `query` is not a convex shape (see isConvexQueryShape).
bool overlaps(const ShapeDesc& query, const Transform& pose, const ShapeDesc& target, const Transform& target_pose);

}  // namespace cairn
