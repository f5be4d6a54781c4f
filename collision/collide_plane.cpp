// Every convex shape against a plane (the plane is shape A, the solid
// half-space n.x <= d; the normal from A toward B is the plane's n).
//
// A point x of B lies at separation sep = n.x - d from the plane; the
// contact for it has depth -sep and sits halfway between x and its
// projection, x - n sep / 2. What differs per shape is which points can be
// the deepest:
//   sphere    c - r n                          (1 point)
//   capsule   both segment ends, each minus r n (2 points when lying down)
//   box       the 8 corners                     (4 when resting on a face)
//   hull      every vertex
//   cylinder  per cap, the deepest rim point c_cap + r w, with
//             w = -(n - a (a.n)) / |n - a (a.n)| (the plane normal's part
//             across the axis a, reversed), and the rim points at 90, 180
//             and 270 degrees from it: 4 per cap, 8 candidates. Standing
//             upright (w undefined) the body's x axis replaces w, so a
//             standing cylinder keeps 4 fixed rim points.
// Candidates farther than the margin are dropped and the 4 spanning the
// largest area kept (clip.hpp). Feature id: corner, end, vertex or rim
// index.
#include "collision/clip.hpp"
#include "collision/narrowphase.hpp"
#include "collision/support.hpp"

namespace cairn::narrow {

int planeConvex(const ShapeDesc& plane, const Transform& tp, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  Vec3 n;
  Real d;
  worldPlane(plane, tp, n, d);
  const Mat3 r = tb.q.toRotationMatrix();

  // Candidate surface points of B (world) and their ids.
  constexpr int kMaxCandidates = 8;
  Vec3 cand[kMaxCandidates];
  std::uint32_t cand_id[kMaxCandidates];
  int nc = 0;
  // Hulls can have any number of vertices within the margin: reused
  // per-thread buffers keep this allocation-free after the first calls.
  thread_local std::vector<Vec3> hull_pos;
  thread_local std::vector<Real> hull_depth;
  thread_local std::vector<std::uint32_t> hull_id;
  hull_pos.clear();
  hull_depth.clear();
  hull_id.clear();

  switch (b.type) {
    case ShapeType::Sphere:
      cand[nc] = tb.p - n * b.radius;
      cand_id[nc++] = 0;
      break;
    case ShapeType::Capsule: {
      const Vec3 a = r.col(1) * b.half_height;
      cand[nc] = tb.p - a - n * b.radius;
      cand_id[nc++] = 0;
      cand[nc] = tb.p + a - n * b.radius;
      cand_id[nc++] = 1;
      break;
    }
    case ShapeType::Box:
      for (int k = 0; k < 8; ++k) {
        const Vec3 local((k & 1) ? b.half_extents.x() : -b.half_extents.x(), (k & 2) ? b.half_extents.y() : -b.half_extents.y(),
                         (k & 4) ? b.half_extents.z() : -b.half_extents.z());
        cand[nc] = tb.p + r * local;
        cand_id[nc++] = static_cast<std::uint32_t>(k);
      }
      break;
    case ShapeType::Cylinder: {
      const Vec3 a = r.col(1);
      Vec3 w = -(n - a * a.dot(n));
      const Real len = w.norm();
      w = len > Real(1e-3) ? Vec3(w / len) : Vec3(r.col(0));
      const Vec3 v = a.cross(w);
      for (int cap = 0; cap < 2; ++cap) {
        const Vec3 center = tb.p + a * (cap ? -b.half_height : b.half_height);
        const Vec3 dirs[4] = {w, v, -w, -v};
        for (int k = 0; k < 4; ++k) {
          cand[nc] = center + dirs[k] * b.radius;
          cand_id[nc++] = static_cast<std::uint32_t>(cap * 4 + k);
        }
      }
      break;
    }
    case ShapeType::ConvexHull: {
      if (!b.hull) return 0;
      const auto& verts = b.hull->vertices;
      for (size_t k = 0; k < verts.size(); ++k) {
        const Vec3 x = tb.p + r * verts[k];
        const Real sep = n.dot(x) - d;
        if (sep > margin) continue;
        hull_pos.push_back(x - n * (Real(0.5) * sep));
        hull_depth.push_back(-sep);
        hull_id.push_back(static_cast<std::uint32_t>(k));
      }
      break;
    }
    case ShapeType::Plane:
    case ShapeType::Mesh: return 0;
  }

  Vec3 pos[kMaxCandidates];
  Real depth[kMaxCandidates];
  std::uint32_t ids[kMaxCandidates];
  int kept = 0;
  for (int k = 0; k < nc; ++k) {
    const Real sep = n.dot(cand[k]) - d;
    if (sep > margin) continue;
    pos[kept] = cand[k] - n * (Real(0.5) * sep);
    depth[kept] = -sep;
    ids[kept++] = cand_id[k];
  }
  const Vec3* p = hull_pos.empty() ? pos : hull_pos.data();
  const Real* dp = hull_pos.empty() ? depth : hull_depth.data();
  const std::uint32_t* ip = hull_pos.empty() ? ids : hull_id.data();
  const int count = hull_pos.empty() ? kept : static_cast<int>(hull_pos.size());
  if (count == 0) return 0;
  int keep[4];
  Manifold& m = out.emplace_back();
  m.normal = n;
  m.count = reduceToFour(p, dp, count, n, keep);
  for (int k = 0; k < m.count; ++k) m.points[k] = ContactPoint{p[keep[k]], dp[keep[k]], ip[keep[k]]};
  return 1;
}

}  // namespace cairn::narrow
