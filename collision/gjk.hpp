// GJK distance between two convex shapes (Gilbert, Johnson, Keerthi 1988,
// in the form of van den Bergen, "A Fast and Robust GJK Implementation for
// Collision Detection of Convex Objects", JGT 1999).
//
// The distance between A and B is the distance from the origin to their
// Minkowski difference D = A - B = {a - b}, whose support mapping is
//   s_D(d) = s_A(d) - s_B(-d).
// GJK keeps a simplex W of at most 4 points of D and the point v of conv(W)
// nearest the origin. Each iteration adds w = s_D(-v) and replaces W by the
// smallest subset whose hull still contains the new nearest point (Johnson's
// sub-algorithm, here as the closest-point-on-simplex region tests of
// Ericson, "Real-Time Collision Detection", 5.1.5 and 5.1.6). It stops when
//   |v|^2 - v.w <= eps |v|^2
// (v.w / |v| is a lower bound and |v| an upper bound of the distance, so the
// distance is known to relative accuracy eps = 1e-13, and the direction of v
// to sqrt(2 eps)), when w repeats a simplex
// point (a polytope's exact answer), or when W encloses the origin (overlap).
// The closest points follow from the barycentric weights of v:
//   a = sum l_i a_i, b = sum l_i b_i, with w_i = a_i - b_i.
// Early out: v.w / |v| > max_distance proves the shapes are farther apart
// than the caller cares about.
#pragma once

#include "collision/convex_proxy.hpp"

namespace cairn {

struct SimplexVertex {
  Vec3 w, a, b;  // w = a - b: a point of A - B and the support points it came from
};

struct Simplex {
  SimplexVertex v[4];
  Real lambda[4] = {0, 0, 0, 0};
  int count = 0;
};

struct GjkResult {
  bool overlap = false;  // the shapes intersect or touch to within tolerance
  bool beyond = false;   // stopped early: distance > max_distance
  Real distance = 0;     // between the shapes when !overlap
  Vec3 point_a = Vec3::Zero();  // closest points (world)
  Vec3 point_b = Vec3::Zero();
  Simplex simplex;       // the final simplex (EPA starts from it)
  int iterations = 0;
};

// The point v of conv(s) nearest the origin (the Voronoi region tests
// above): reduces s to the vertices whose hull holds v and sets their
// weights. False, leaving s as it was, when s is a tetrahedron that encloses
// the origin.
bool nearestOnSimplex(Simplex& s, Vec3& v);

// full = false runs on the cores (sphere: center, capsule: segment) and
// reports their distance; the caller subtracts the radii.
GjkResult gjkDistance(const ConvexProxy& a, const ConvexProxy& b, bool full, Real max_distance = kInf);

// Support point of A - B in direction d, with its two sources.
inline SimplexVertex minkowskiSupport(const ConvexProxy& a, const ConvexProxy& b, const Vec3& d, bool full) {
  SimplexVertex s;
  s.a = a.support(d, full);
  s.b = b.support(-d, full);
  s.w = s.a - s.b;
  return s;
}

}  // namespace cairn
