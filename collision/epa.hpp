// Expanding Polytope Algorithm: penetration depth and direction of two
// intersecting convex shapes (van den Bergen, "Proximity Queries and
// Penetration Depth Computation on 3D Game Objects", GDC 2001).
//
// When A and B overlap the origin lies inside D = A - B. The penetration
// depth is the distance from the origin to the boundary of D,
//   depth = min over unit u of h_D(u),   h_D(u) = h_A(u) + h_B(-u),
// and the minimizing u is the normal from A toward B (translating B by
// depth * u separates the shapes). EPA grows a polytope inside D from GJK's
// final simplex: take the polytope face nearest the origin (normal u,
// distance t), add w = s_D(u); if u.w - t is below tolerance, that face is on
// the boundary of D and (u, t) is the answer; otherwise w replaces every face
// it can see, and the horizon of those faces is joined to w.
//
// Fixed capacity (no allocation); when it runs out, the nearest face so far
// is returned: its distance is a lower bound on the depth and is within the
// last gap u.w - t of the true value.
#pragma once

#include "collision/gjk.hpp"

namespace cairn {

struct EpaResult {
  bool ok = false;       // false if D has no volume (e.g. a point against a triangle)
  Vec3 normal = Vec3::UnitY();  // unit, from A toward B
  Real depth = 0;
  Vec3 point_a = Vec3::Zero();  // deepest points of A into B and of B into A (world)
  Vec3 point_b = Vec3::Zero();
  int iterations = 0;
};

EpaResult epaPenetration(const ConvexProxy& a, const ConvexProxy& b, bool full, const Simplex& start);

}  // namespace cairn
