// Ray casts against triangle meshes: the segment walks the mesh's BVH
// nearest node first (castMeshTriangles, mesh_bvh.hpp), each hit clipping
// the segment, and each candidate triangle is tested by Moller-Trumbore.
//
// Moller and Trumbore, JGT 1997: with e1 = b - a, e2 = c - a, s = o - a, the
// point o + f d = a + u e1 + v e2 solves, by Cramer's rule,
//   det = e1 . (d x e2),  u = s . (d x e2) / det,
//   v = d . (s x e1) / det,  f = e2 . (s x e1) / det,
// and lies in the triangle for u >= 0, v >= 0, u + v <= 1 (edges included:
// a ray through a shared edge hits both triangles, at the same fraction).
// det = -d . (e1 x e2) vanishes when the ray lies in the triangle's plane;
// below 1e-14 |d| |e1 x e2| (the ray within 1e-14 rad of the plane) the
// triangle is skipped: it has no thickness to hit.
#include "collision/mesh_bvh.hpp"
#include "collision/ray_cast.hpp"

namespace cairn {

std::optional<Real> rayTriangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& origin,
                                const Vec3& translation, Real max_fraction) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = translation.cross(e2);
  const Real det = e1.dot(p);
  if (!(std::abs(det) > Real(1e-14) * translation.norm() * e1.cross(e2).norm())) return std::nullopt;
  const Real inv = 1 / det;
  const Vec3 s = origin - a;
  const Real u = s.dot(p) * inv;
  if (u < 0 || u > 1) return std::nullopt;
  const Vec3 q = s.cross(e1);
  const Real v = translation.dot(q) * inv;
  if (v < 0 || u + v > 1) return std::nullopt;
  const Real f = e2.dot(q) * inv;
  if (!(f > 0 && f <= max_fraction)) return std::nullopt;
  return f;
}

std::optional<CastHit> rayCastMeshLocal(const TriangleMeshData& mesh, const Vec3& origin, const Vec3& translation,
                                        Real max_fraction) {
  CastHit best;
  best.fraction = kInf;
  castMeshTriangles(mesh, origin, translation, max_fraction, Vec3::Zero(), [&](int t, Real max_f) {
    const auto& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3& b = mesh.vertices[tri[1]];
    const Vec3& c = mesh.vertices[tri[2]];
    const auto f = rayTriangle(a, b, c, origin, translation, max_f);
    if (f && (*f < best.fraction || (*f == best.fraction && t < best.triangle))) {
      best.fraction = *f;
      best.triangle = t;
      const Vec3 n = (b - a).cross(c - a).normalized();
      best.normal = n.dot(translation) > 0 ? Vec3(-n) : n;  // two-sided: face the origin
    }
    return std::min(max_f, best.fraction);
  });
  if (best.triangle < 0) return std::nullopt;
  best.point = origin + best.fraction * translation;
  return best;
}

}  // namespace cairn
