// Shape casts: the first contact of a convex shape swept along a
// translation against one shape,
//   moving shape at pose + f * translation,  0 <= f <= max_fraction.
//
// The moving shape may be any convex shape (sphere, box, capsule, cylinder,
// convex hull); the target any shape. Result (CastHit, ray_cast.hpp):
//   fraction  time of impact: the smallest f at which the two touch
//             (to within 1e-10 of the shapes' size, never past it).
//   point     the contact point at that time, on the target's surface.
//   normal    unit, the target's outward normal at the contact (it points
//             toward the moving shape; normal . translation <= 0).
//   triangle  the mesh triangle hit, -1 otherwise.
//   inside    the shapes overlap at the start: fraction 0, normal
//             -translation / |translation|, point the moving shape's
//             position. Shapes that merely touch at the start hit at
//             fraction 0 with the contact normal if the motion pushes them
//             together, and miss if it separates them or slides along.
// A zero translation casts nothing.
//
// Per target:
//   convex  GJK ray cast (gjk_raycast.hpp).
//   plane   closed form: the moving shape's deepest point along -n,
//           a* = s(-n), is at height s0 = n.a* - e above the plane
//           n.x <= e and approaches at speed -n.t, so
//           f = s0 / (-n.t)   (s0 >= 0, n.t < 0); s0 < 0 is an overlap.
//   mesh    the moving shape's box, in the mesh's frame, walks the mesh's
//           BVH along the translation (castMeshTriangles), and each
//           candidate triangle is a flat convex proxy for the GJK ray
//           cast; hits clip the walk, ties go to the lowest triangle.
#pragma once

#include "collision/ray_cast.hpp"

namespace cairn {

std::optional<CastHit> shapeCast(const ShapeDesc& moving, const Transform& pose, const Vec3& translation,
                                 const ShapeDesc& target, const Transform& target_pose, Real max_fraction = 1);

// True for the shapes that can be swept or tested for overlap (convex solids
// with their data present).
bool isConvexQueryShape(const ShapeDesc& s);

}  // namespace cairn
