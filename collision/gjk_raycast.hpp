// GJK ray cast: the time of impact of a convex shape A translated along r
// against a convex shape B (van den Bergen, "Ray Casting against General
// Convex Objects with Application to Continuous Collision Detection", 2004).
//
// A + f r touches B when f r lies in C = B - A (the Minkowski difference),
// so the time of impact is where the ray x(f) = f r from the origin enters
// C. GJK keeps a simplex of points p_i of C and v = x - (the point of
// conv{p_i} nearest x); each iteration takes the support point p = s_C(v) =
// s_B(v) - s_A(-v) (every point of C lies behind the plane v.y = v.p) and
//   if v.(x - p) > R |v|: x is outside C grown by R, beyond that plane:
//     if v.r >= 0 the ray never reaches the plane: miss;
//     else advance to it, f -= (v.(x - p) - R |v|) / (v.r), x = f r,
//     and remember the plane's normal n = v;
//   add p to the simplex and recompute v for the new x,
// until |v| <= R + tol (x is within R + tol of C). Every advance stops at a
// plane that all of C grown by R lies behind, so x never passes into it:
// the fraction is conservative and within tol / |r . normal| of exact.
//
// Rounded shapes run on their cores (sphere: its center, capsule: its
// segment) with R = r_A + r_B, as in Box2D's b2ShapeCast: the cores are
// polytopes or points, where GJK terminates exactly, and the normal at the
// hit is v / |v| (|v| = R there). Without rounding (|v| -> 0) the normal is
// that of the last advancing plane, a supporting plane of C through x.
//
// A start within tol of touching never advances. The shapes are then
// classified by the contact routine (GJK / EPA, narrowphase.hpp): deeper
// than tol is an initial overlap (`inside`); merely touching is a hit at
// fraction 0 when A moves into B (r . n_AB > 0) and a miss when it moves
// away or slides along (the convention of ray_cast.hpp).
#pragma once

#include "collision/convex_proxy.hpp"
#include "collision/ray_cast.hpp"

#include <optional>

namespace cairn {

// A (moving along r) against B, both proxies at their start poses. The hit's
// point is on B's surface, its normal B's outward normal (toward A). An
// initial overlap reports fraction 0, inside, the normal -r / |r| and the
// point A's position.
std::optional<CastHit> gjkRaycast(const ConvexProxy& a, const Vec3& r, const ConvexProxy& b, Real max_fraction = 1);

}  // namespace cairn
