// GJK distance (the iteration and its stopping rules are in gjk.hpp).
#include "collision/gjk.hpp"

#include <algorithm>

namespace cairn {
namespace {

// Nearest point to the origin on segment (w0, w1); reduces the simplex to
// the vertices whose region contains it.
Vec3 solveSegment(Simplex& s) {
  const Vec3 a = s.v[0].w, b = s.v[1].w;
  const Vec3 ab = b - a;
  const Real len2 = ab.squaredNorm();
  const Real t = len2 > 0 ? -a.dot(ab) / len2 : Real(0);
  if (t <= 0) {
    s.count = 1;
    s.lambda[0] = 1;
    return a;
  }
  if (t >= 1) {
    s.v[0] = s.v[1];
    s.count = 1;
    s.lambda[0] = 1;
    return b;
  }
  s.lambda[0] = 1 - t;
  s.lambda[1] = t;
  return a + t * ab;
}

// Nearest point to the origin on triangle (w0, w1, w2) by Voronoi regions:
// the origin's projections onto the edges (d1..d6) decide whether a vertex,
// an edge or the face is nearest; the face case uses the barycentric
// coordinates from the signed sub-areas va, vb, vc.
Vec3 solveTriangle(Simplex& s) {
  const SimplexVertex A = s.v[0], B = s.v[1], C = s.v[2];
  const Vec3 a = A.w, b = B.w, c = C.w;
  const Vec3 ab = b - a, ac = c - a;
  auto keep1 = [&](const SimplexVertex& x) {
    s.v[0] = x;
    s.count = 1;
    s.lambda[0] = 1;
    return x.w;
  };
  auto keep2 = [&](const SimplexVertex& x, const SimplexVertex& y, Real t) {
    s.v[0] = x;
    s.v[1] = y;
    s.count = 2;
    s.lambda[0] = 1 - t;
    s.lambda[1] = t;
    return Vec3(x.w + t * (y.w - x.w));
  };
  const Real d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) return keep1(A);
  const Real d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) return keep1(B);
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return keep2(A, B, d1 / (d1 - d3));
  const Real d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) return keep1(C);
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return keep2(A, C, d2 / (d2 - d6));
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return keep2(B, C, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const Real sum = va + vb + vc;
  if (!(sum > 0)) {
    // Degenerate (collinear) triangle that slipped past the region tests:
    // the best of its edges.
    Simplex e1 = s, e2 = s, e3 = s;
    e2.v[1] = C;
    e3.v[0] = B;
    e3.v[1] = C;
    e1.count = e2.count = e3.count = 2;
    Vec3 p1 = solveSegment(e1), p2 = solveSegment(e2), p3 = solveSegment(e3);
    Simplex* best = &e1;
    Vec3 bp = p1;
    if (p2.squaredNorm() < bp.squaredNorm()) best = &e2, bp = p2;
    if (p3.squaredNorm() < bp.squaredNorm()) best = &e3, bp = p3;
    s = *best;
    return bp;
  }
  // Face region. The sub-areas above are differences of products of dot
  // products: when the triangle is small next to its distance from the
  // origin (GJK closing in on a curved surface) they cancel badly. The
  // projection of the origin on the plane, n (n.a) / |n|^2, and sub-areas
  // measured from that point lose nothing.
  const Vec3 n = ab.cross(ac);
  const Real n2 = n.squaredNorm();
  const Vec3 p = n * (n.dot(a) / n2);
  const Real la = (b - p).cross(c - p).dot(n) / n2;
  const Real lb = (c - p).cross(a - p).dot(n) / n2;
  s.lambda[0] = la;
  s.lambda[1] = lb;
  s.lambda[2] = 1 - la - lb;
  return p;
}

// Nearest point to the origin on tetrahedron (w0..w3): the origin is inside
// unless it lies beyond a face plane (on the side away from the opposite
// vertex); then the nearest point is on one of those faces. Returns false
// (and leaves s alone) when the origin is inside.
bool solveTetrahedron(Simplex& s, Vec3& v) {
  static const int kFaces[4][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 3, 2, 0}};
  const Vec3 c = (s.v[0].w + s.v[1].w + s.v[2].w + s.v[3].w) * Real(0.25);
  const Real size2 = std::max({(s.v[0].w - c).squaredNorm(), (s.v[1].w - c).squaredNorm(),
                               (s.v[2].w - c).squaredNorm(), (s.v[3].w - c).squaredNorm()});
  bool any_outside = false;
  Real best = kInf;
  Simplex best_s;
  for (const auto& f : kFaces) {
    const Vec3 a = s.v[f[0]].w, b = s.v[f[1]].w, cc = s.v[f[2]].w, d = s.v[f[3]].w;
    const Vec3 n = (b - a).cross(cc - a);
    const Real side_origin = -n.dot(a);
    const Real side_d = n.dot(d - a);
    // A flat tetrahedron (|side_d| tiny) has no inside: test every face.
    const bool flat = std::abs(side_d) <= Real(1e-12) * n.norm() * std::sqrt(size2);
    if (!flat && side_origin * side_d >= 0) continue;  // origin on the inner side
    any_outside = true;
    Simplex t;
    t.count = 3;
    t.v[0] = s.v[f[0]];
    t.v[1] = s.v[f[1]];
    t.v[2] = s.v[f[2]];
    const Vec3 p = solveTriangle(t);
    if (p.squaredNorm() < best) {
      best = p.squaredNorm();
      best_s = t;
      v = p;
    }
  }
  if (!any_outside) return false;
  s = best_s;
  return true;
}

}  // namespace

bool nearestOnSimplex(Simplex& s, Vec3& v) {
  switch (s.count) {
    case 1:
      s.lambda[0] = 1;
      v = s.v[0].w;
      return true;
    case 2: v = solveSegment(s); return true;
    case 3: v = solveTriangle(s); return true;
    default: return solveTetrahedron(s, v);
  }
}

GjkResult gjkDistance(const ConvexProxy& pa, const ConvexProxy& pb, bool full, Real max_distance) {
  GjkResult r;
  Simplex& s = r.simplex;
  const Real scale = std::max(pa.scale, pb.scale);
  // Below this the shapes touch: the direction of v is round-off.
  const Real touch2 = Real(1e-20) * scale * scale;
  // Relative accuracy of the distance for curved shapes; polytopes stop
  // earlier, exactly, on a repeated vertex. The direction of v is only known
  // to sqrt(2 eps) (|v - v*|^2 <= |v|^2 - |v*|^2), and where the nearest
  // feature is a rim (a kink of the support function) a direction error
  // costs depth linearly, so eps is near the round-off of |v|^2.
  const Real eps = Real(1e-13);

  Vec3 v = pa.center() - pb.center();
  if (v.squaredNorm() <= touch2) v = Vec3::UnitX();
  Real prev_v2 = kInf;
  for (int iter = 0; iter < 64; ++iter) {
    r.iterations = iter + 1;
    const SimplexVertex w = minkowskiSupport(pa, pb, -v, full);
    const Real vw = v.dot(w.w);
    const Real v2 = v.squaredNorm();
    if (s.count > 0 && vw > 0 && vw * vw > max_distance * max_distance * v2) {
      r.beyond = true;
      r.distance = vw / std::sqrt(v2);
      return r;
    }
    bool repeated = false;
    for (int i = 0; i < s.count; ++i) repeated |= (s.v[i].w - w.w).squaredNorm() <= touch2;
    if (s.count > 0 && (repeated || v2 - vw <= eps * v2)) break;

    s.v[s.count++] = w;
    if (!nearestOnSimplex(s, v)) {
      r.overlap = true;
      return r;
    }
    const Real nv2 = v.squaredNorm();
    if (nv2 <= touch2) {
      r.overlap = true;
      return r;
    }
    // No progress: round-off has taken over; the current v is as good as it gets.
    if (nv2 >= prev_v2) break;
    prev_v2 = nv2;
  }
  r.point_a = Vec3::Zero();
  r.point_b = Vec3::Zero();
  for (int i = 0; i < s.count; ++i) {
    r.point_a += s.lambda[i] * s.v[i].a;
    r.point_b += s.lambda[i] * s.v[i].b;
  }
  r.distance = (r.point_a - r.point_b).norm();
  if (r.distance * r.distance <= touch2) r.overlap = true;
  return r;
}

}  // namespace cairn
