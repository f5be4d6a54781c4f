// Any two convex shapes: GJK on the cores for the distance, EPA for the
// penetration, then the reference-face clipping of contact_features.hpp for
// the full manifold. This is the path of cylinders and hulls, and the
// fallback of the dedicated routines.
//
//   cores apart (GJK distance t > 0):
//     n = (b - a) / t from GJK's closest points a, b;
//     depth = r_a + r_b - t; surface points a + r_a n, b - r_b n.
//   cores overlap: EPA on the cores, depth = EPA depth + r_a + r_b (growing
//     both shapes by a ball grows every support distance h_D(u) by
//     r_a + r_b, so the minimizing direction stays the same). If the cores'
//     difference is flat (a sphere's center on a mesh triangle), EPA runs on
//     the whole shapes instead.
//   EPA failing too (degenerate input) falls back to the direction between
//   the centers and the support distance along it: finite, never NaN.
#include "collision/contact_features.hpp"
#include "collision/epa.hpp"
#include "collision/gjk.hpp"
#include "collision/narrowphase.hpp"

namespace cairn::narrow {

bool convexSeparation(const ConvexProxy& a, const ConvexProxy& b, Real margin, Separation& out) {
  const Real ra = a.radius, rb = b.radius;
  const GjkResult g = gjkDistance(a, b, false, ra + rb + margin);
  if (g.beyond) return false;
  Vec3& n = out.normal;
  Vec3& wa = out.point_a;
  Vec3& wb = out.point_b;
  Real& depth = out.depth;
  if (!g.overlap) {
    if (g.distance - ra - rb > margin) return false;
    n = (g.point_b - g.point_a) / g.distance;
    depth = ra + rb - g.distance;
    wa = g.point_a + n * ra;
    wb = g.point_b - n * rb;
  } else {
    EpaResult e = epaPenetration(a, b, false, g.simplex);
    bool cores = true;
    if (!e.ok) {
      const GjkResult gf = gjkDistance(a, b, true);
      e = epaPenetration(a, b, true, gf.simplex);
      cores = false;
    }
    if (e.ok) {
      n = e.normal;
      depth = e.depth + (cores ? ra + rb : Real(0));
      wa = e.point_a + n * (cores ? ra : Real(0));
      wb = e.point_b - n * (cores ? rb : Real(0));
    } else {
      const Vec3 c = b.center() - a.center();
      n = c.norm() > 0 ? Vec3(c.normalized()) : Vec3::UnitY();
      wa = a.support(n, true);
      wb = b.support(-n, true);
      depth = n.dot(wa - wb);
    }
  }
  return true;
}

bool convexProxies(const ConvexProxy& a, const ConvexProxy& b, Real margin, Manifold& m) {
  Separation s;
  if (!convexSeparation(a, b, margin, s)) return false;
  return buildManifold(a, b, s.normal, s.depth, s.point_a, s.point_b, margin, m);
}

int convexConvex(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  if ((a.type == ShapeType::ConvexHull && !a.hull) || (b.type == ShapeType::ConvexHull && !b.hull)) return 0;
  Manifold m;
  if (!convexProxies(makeProxy(a, ta), makeProxy(b, tb), margin, m)) return 0;
  out.push_back(m);
  return 1;
}

}  // namespace cairn::narrow
