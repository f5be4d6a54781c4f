// Ray casts against one shape: where the segment
//   x(f) = origin + f * translation,  0 <= f <= max_fraction
// first enters the shape placed at pose t (t already includes shape.local).
//
// Conventions (shared with shape casts, shape_cast.hpp, and the broadphase
// front end, queries.hpp):
//   fraction  the smallest f at which the segment enters the closed solid;
//             the hit point is origin + fraction * translation.
//   normal    unit, world space, the outward normal of the surface at the
//             hit point (so normal . translation <= 0).
//   triangle  the mesh triangle hit, -1 for every other shape.
//   inside    the origin lies strictly inside the solid: fraction 0, point
//             the origin, normal -translation / |translation| (there is no
//             surface to report; overlap.hpp and the contact routines give
//             depths). Jolt's default (RayCastSettings::mTreatConvexAsSolid)
//             also reports fraction 0; Box2D v3.0 treats an initial overlap
//             as a miss. A solid hit at 0 keeps a ray fired from inside a
//             wall from passing through it.
// A ray that starts on the surface hits at fraction 0 if it moves into the
// solid and misses if it moves out or along the surface (so a ray fired from
// a resting contact point away from the surface does not hit it again). A
// ray from outside that only grazes the surface hits it (closed solids).
// A zero translation casts nothing (no hit), as in Box2D.
//
// Planes are solid half-spaces. Mesh triangles are two-sided and have no
// inside (as in the narrowphase): the normal is the triangle's, turned to
// face the ray's origin, and a ray starting on a triangle or lying in its
// plane does not hit it.
#pragma once

#include "cairn/shape.hpp"

#include <optional>

namespace cairn {

struct CastHit {
  Real fraction = 0;
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();
  int triangle = -1;
  bool inside = false;
};

std::optional<CastHit> rayCast(const ShapeDesc& shape, const Transform& t, const Vec3& origin, const Vec3& translation,
                               Real max_fraction = 1);

// The mesh case (ray_cast_mesh.cpp), with the segment already in the mesh's
// frame; the hit's point and normal are in that frame too. Ties between
// triangles go to the lowest triangle index.
std::optional<CastHit> rayCastMeshLocal(const TriangleMeshData& mesh, const Vec3& origin, const Vec3& translation,
                                        Real max_fraction);

// Moller and Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
// JGT 1997; two-sided. The fraction f with 0 < f <= max_fraction at which
// the segment crosses triangle (a, b, c), edges included, or nothing.
std::optional<Real> rayTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& origin, const Vec3& translation,
                                Real max_fraction);

}  // namespace cairn
