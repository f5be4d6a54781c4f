// Support mappings: the farthest point of a convex shape in a direction,
//   s(d) = argmax_{x in shape} d.x,
// the one query GJK and EPA ask of a shape (van den Bergen, "Collision
// Detection in Interactive 3D Environments", 2003, ch. 4).
//
// Rounded shapes split into a core and a radius: a sphere is its center
// point grown by r, a capsule its segment grown by r, so
//   s_full(d) = s_core(d) + r d / |d|.
// GJK runs on cores (exact and fast to converge: a point or a segment has no
// curvature) and adds the radii afterwards; box, cylinder and hull are their
// own core with radius 0.
//
// Closed forms in the shape frame, for d = (dx, dy, dz), sgn(0) = +1:
//   box       (sgn dx hx, sgn dy hy, sgn dz hz)
//   segment   (0, sgn dy hh, 0)                         capsule core
//   cylinder  (0, sgn dy hh, 0) + r (dx, 0, dz) / |(dx, 0, dz)|
//             (the cap center when d is along the axis)
//   hull      the vertex maximizing d.v (linear scan: hulls are small)
#pragma once

#include "cairn/shape.hpp"
#include "cairn/math.hpp"

namespace cairn {

// Radius by which the core is grown: r for spheres and capsules, else 0.
Real coreRadius(const ShapeDesc& s);

// Support point of the core in the shape's frame. Planes and meshes are not
// convex solids: a mesh answers with its vertices' hull, a plane with the
// point of its boundary nearest the shape origin.
Vec3 supportCoreLocal(const ShapeDesc& s, const Vec3& d);

// Support point of the whole shape (core plus radius) in the shape's frame.
Vec3 supportLocal(const ShapeDesc& s, const Vec3& d);

// Support point of the whole shape in world space, shape placed at t.
inline Vec3 supportWorld(const ShapeDesc& s, const Transform& t, const Vec3& d_world) {
  return t.apply(supportLocal(s, t.q.conjugate() * d_world));
}

// The plane of a plane shape in world space as a unit normal n and offset d
// (solid where n.x <= d). The description's normal need not be unit:
// n.x <= offset scales to n/|n| . x <= offset/|n|.
inline void worldPlane(const ShapeDesc& s, const Transform& t, Vec3& n, Real& d) {
  const Real len = s.normal.norm();
  n = t.q * (s.normal / len);
  d = s.offset / len + n.dot(t.p);
}

// Index of the hull vertex maximizing d.v (the lowest index on ties, so the
// answer is deterministic).
int hullSupportIndex(const ConvexHullData& h, const Vec3& d);

}  // namespace cairn
