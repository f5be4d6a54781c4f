// GJK ray cast (the iteration and its conventions are in gjk_raycast.hpp).
#include "collision/gjk_raycast.hpp"

#include "collision/gjk.hpp"
#include "collision/narrowphase.hpp"

namespace cairn {
namespace {

// Hits are found to within kTolerance of the shapes' size: the distance at
// which x counts as touching C. Polytope cores terminate exactly well before
// it; a curved core (cylinder) converges linearly and needs a few more
// iterations per decade.
constexpr Real kTolerance = Real(1e-10);
// An exhausted iteration budget still counts as a hit this close.
constexpr Real kLooseTolerance = Real(1e-6);
constexpr int kMaxIterations = 128;
// Below this angle (rad) to the contact plane a motion from touching slides.
constexpr Real kSlideAngle = Real(1e-8);

// With x on the boundary of C to round-off a tetrahedron can enclose it; the
// nearest point is then on the face of the tetrahedron nearest the origin.
void nearestFace(Simplex& s, Vec3& v) {
  static const int kFaces[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  Real best = kInf;
  Simplex best_s = s;
  for (const auto& f : kFaces) {
    Simplex t;
    t.count = 3;
    for (int k = 0; k < 3; ++k) t.v[k] = s.v[f[k]];
    Vec3 p;
    nearestOnSimplex(t, p);
    if (p.squaredNorm() < best) best = p.squaredNorm(), best_s = t, v = p;
  }
  s = best_s;
}

// The shapes touch or overlap at the start (see gjk_raycast.hpp).
std::optional<CastHit> startContact(const ConvexProxy& a, const Vec3& r, const ConvexProxy& b, Real tol, Real loose) {
  narrow::Separation sep;
  CastHit hit;
  hit.fraction = 0;
  if (narrow::convexSeparation(a, b, loose, sep) && sep.depth <= tol) {
    // Moving away, or sliding along. The contact normal of touching shapes
    // comes from GJK (round-off, ~1e-15 rad) or EPA (its stopping gap,
    // 1e-8 of the size): a motion within 1e-8 rad of the tangent plane
    // slides.
    if (!(sep.normal.dot(r) > kSlideAngle * r.norm())) return std::nullopt;
    hit.normal = -sep.normal;
    hit.point = sep.point_b;
    return hit;
  }
  hit.inside = true;
  hit.normal = -r.normalized();
  hit.point = a.p;
  return hit;
}

}  // namespace

std::optional<CastHit> gjkRaycast(const ConvexProxy& a, const Vec3& r, const ConvexProxy& b, Real max_fraction) {
  if (r.squaredNorm() == 0) return std::nullopt;
  const Real R = a.radius + b.radius;
  const Real scale = std::max(a.scale, b.scale);
  const Real tol = kTolerance * scale, touch2 = Real(1e-20) * scale * scale;
  Simplex s;
  Real f = 0;
  Vec3 x = Vec3::Zero();
  Vec3 n = Vec3::Zero();  // normal of the last advancing plane
  Vec3 v = a.center() - b.center();
  if (v.squaredNorm() <= touch2) v = -r;
  Real prev_v2 = kInf;
  for (int iter = 0; iter < kMaxIterations; ++iter) {
    SimplexVertex p;
    p.a = a.supportCore(-v);
    p.b = b.supportCore(v);
    const Vec3 w = x - (p.b - p.a);
    const Real vn = v.norm(), vw = v.dot(w);
    bool advanced = false;
    if (vw > R * vn) {
      const Real vr = v.dot(r);
      if (vr >= 0) return std::nullopt;
      f -= (vw - R * vn) / vr;
      if (f > max_fraction) return std::nullopt;
      x = f * r;
      n = v;
      for (int i = 0; i < s.count; ++i) s.v[i].w = x + s.v[i].a - s.v[i].b;
      advanced = true;
      prev_v2 = kInf;
    }
    bool repeated = false;
    for (int i = 0; i < s.count; ++i) repeated |= ((s.v[i].b - s.v[i].a) - (p.b - p.a)).squaredNorm() <= touch2;
    if (repeated && !advanced) break;  // converged at this x
    if (!repeated) {
      p.w = x - (p.b - p.a);
      s.v[s.count++] = p;
    }
    if (!nearestOnSimplex(s, v)) {
      if (f == 0) return startContact(a, r, b, tol, kLooseTolerance * scale);
      nearestFace(s, v);
      break;
    }
    const Real v2 = v.squaredNorm();
    if (v2 <= (R + tol) * (R + tol)) break;
    if (!advanced && v2 >= prev_v2) break;  // no progress: round-off has taken over
    prev_v2 = v2;
  }
  if (v.norm() > R + kLooseTolerance * scale) return std::nullopt;
  if (f == 0) return startContact(a, r, b, tol, kLooseTolerance * scale);

  CastHit hit;
  hit.fraction = f;
  const Real vn = v.norm();
  hit.normal = vn > tol ? Vec3(v / vn) : Vec3(n.normalized());
  Vec3 on_b = Vec3::Zero();
  for (int i = 0; i < s.count; ++i) on_b += s.lambda[i] * s.v[i].b;
  hit.point = on_b + b.radius * hit.normal;
  return hit;
}

}  // namespace cairn
