// Supporting features and reference-face clipping (see contact_features.hpp).
#include "collision/contact_features.hpp"

#include "collision/closest_points.hpp"
#include "collision/support.hpp"

#include <algorithm>

namespace cairn {
namespace {

void setPlane(Feature& f) { f.offset = f.normal.dot(f.v[0]); }

void hullFeature(const ConvexProxy& p, const Vec3& dir, Feature& f) {
  const ConvexHullData& h = *p.hull;
  const Vec3 dl = p.r.transpose() * dir;
  const int sv = hullSupportIndex(h, dl);
  int best = -1;
  Real best_cos = -kInf;
  for (int i = 0; i < static_cast<int>(h.faces.size()); ++i) {
    const Real c = h.face_normals[i].dot(dl);
    if (c <= best_cos) continue;
    if (std::find(h.faces[i].begin(), h.faces[i].end(), sv) == h.faces[i].end()) continue;
    best_cos = c;
    best = i;
  }
  if (best < 0 || static_cast<int>(h.faces[best].size()) > Feature::kMaxVerts) {
    f.count = 1;
    f.v[0] = p.p + p.r * h.vertices[sv];
    f.index = sv;
    return;
  }
  const auto& loop = h.faces[best];
  f.count = static_cast<int>(loop.size());
  for (int k = 0; k < f.count; ++k) f.v[k] = p.p + p.r * h.vertices[loop[k]];
  f.normal = p.r * h.face_normals[best];
  f.index = best;
  setPlane(f);
}

void cylinderFeature(const ConvexProxy& p, const Vec3& dir, Feature& f) {
  const Vec3 a = p.r.col(1);
  const Real c = a.dot(dir);
  Vec3 radial = dir - a * c;
  const Real len = radial.norm();
  // Nearly along the axis the deepest rim direction is round-off; a fixed
  // body axis keeps the rim points (and their ids) still.
  radial = len > Real(1e-3) ? Vec3(radial / len) : Vec3(p.r.col(0));
  const Real rr = p.cylinder_radius, hh = p.half_height;
  if (std::abs(c) >= Real(0.5)) {
    const Real s = c < 0 ? Real(-1) : Real(1);
    const Vec3 cap = p.p + a * (s * hh);
    const Vec3 side = s * a.cross(radial);  // radial x side = s a: counter-clockwise about s a
    constexpr int kRim = 8;
    f.count = kRim;
    for (int k = 0; k < kRim; ++k) {
      const Real ang = 2 * kPi * k / kRim;
      f.v[k] = cap + rr * (std::cos(ang) * radial + std::sin(ang) * side);
    }
    f.normal = s * a;
    f.index = s > 0 ? 0 : 1;
    setPlane(f);
    return;
  }
  // The side: the line of deepest points from cap to cap.
  f.count = 2;
  f.v[0] = p.p - a * hh + rr * radial;
  f.v[1] = p.p + a * hh + rr * radial;
  f.index = 2;
}

}  // namespace

void boxFace(const Vec3& center, const Mat3& rot, const Vec3& half, int face, Feature& f) {
  const int i = face >> 1, j = (i + 1) % 3, k = (i + 2) % 3;
  const Real s = (face & 1) ? Real(-1) : Real(1);
  // Corners in (j, k) order counter-clockwise about +e_i; reversed for -e_i.
  static const Real kUV[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
  const Vec3 c = center + rot.col(i) * (s * half[i]);
  f.count = 4;
  for (int m = 0; m < 4; ++m) {
    const int q = s > 0 ? m : 3 - m;
    f.v[m] = c + rot.col(j) * (kUV[q][0] * half[j]) + rot.col(k) * (kUV[q][1] * half[k]);
  }
  f.normal = rot.col(i) * s;
  f.index = face;
  f.radius = 0;
  setPlane(f);
}

void supportFeature(const ConvexProxy& p, const Vec3& dir, Feature& f) {
  f.radius = p.radius;
  f.index = 0;
  switch (p.kind) {
    case ConvexProxy::Kind::Point:
      f.count = 1;
      f.v[0] = p.p;
      return;
    case ConvexProxy::Kind::Segment: {
      const Vec3 a = p.r.col(1);
      const Vec3 e0 = p.p - a * p.half_height, e1 = p.p + a * p.half_height;
      if (std::abs(a.dot(dir)) < kSegmentSin) {
        f.count = 2;
        f.v[0] = e0;
        f.v[1] = e1;
        f.index = 2;
      } else {
        f.count = 1;
        f.index = a.dot(dir) > 0 ? 1 : 0;
        f.v[0] = f.index ? e1 : e0;
      }
      return;
    }
    case ConvexProxy::Kind::Box: {
      const Vec3 dl = p.r.transpose() * dir;
      int i = 0;
      dl.cwiseAbs().maxCoeff(&i);
      boxFace(p.p, p.r, p.half_extents, 2 * i + (dl[i] < 0 ? 1 : 0), f);
      return;
    }
    case ConvexProxy::Kind::Cylinder: cylinderFeature(p, dir, f); return;
    case ConvexProxy::Kind::Hull: hullFeature(p, dir, f); return;
    case ConvexProxy::Kind::Polygon: {
      const Vec3 n = (p.poly[1] - p.poly[0]).cross(p.poly[2] - p.poly[0]);
      const Real len = n.norm();
      if (!(len > 0)) {
        f.count = 1;
        f.v[0] = p.supportCore(dir);
        return;
      }
      const bool front = n.dot(dir) >= 0;
      f.count = 3;
      f.v[0] = p.poly[0];
      f.v[1] = front ? p.poly[1] : p.poly[2];
      f.v[2] = front ? p.poly[2] : p.poly[1];
      f.normal = (front ? n : Vec3(-n)) / len;
      f.index = front ? 0 : 1;
      setPlane(f);
      return;
    }
  }
}

int faceContact(const Feature& ref, const Feature& inc, bool ref_is_b, Real margin, Manifold& m, const ContactPoint* deepest) {
  ClipVertex buf_a[kMaxClipVerts], buf_b[kMaxClipVerts];
  int n = inc.count;
  for (int k = 0; k < n; ++k) buf_a[k] = ClipVertex{inc.v[k], static_cast<std::uint16_t>(k), static_cast<std::uint8_t>(k)};
  ClipVertex* cur = buf_a;
  ClipVertex* next = buf_b;
  // Side planes have a sliver of slack so that an incident point exactly on
  // the reference face's rim (a box flush with a box) is not lost to
  // round-off.
  Real size = 0;
  for (int k = 0; k < ref.count; ++k) size = std::max(size, (ref.v[k] - ref.v[0]).norm());
  const Real slack = Real(1e-9) * size;
  for (int e = 0; e < ref.count && n > 0; ++e) {
    const Vec3& p = ref.v[e];
    const Vec3& q = ref.v[(e + 1) % ref.count];
    Vec3 s = (q - p).cross(ref.normal);
    const Real len = s.norm();
    if (!(len > 0)) continue;
    s /= len;
    n = clipByPlane(cur, n, s, s.dot(p) + slack, e, next);
    std::swap(cur, next);
  }
  Vec3 pos[kMaxClipVerts];
  Real depth[kMaxClipVerts];
  std::uint32_t ids[kMaxClipVerts];
  int kept = 0;
  const std::uint32_t base = (ref_is_b ? 0x80000000u : 0u) | ((static_cast<std::uint32_t>(ref.index) & 0x7F) << 24) |
                             ((static_cast<std::uint32_t>(inc.index) & 0xFF) << 16);
  for (int k = 0; k < n; ++k) {
    const Vec3 surf = cur[k].p - ref.normal * inc.radius;  // incident surface point
    const Real sep = ref.normal.dot(surf) - ref.offset;
    if (sep > margin) continue;
    pos[kept] = surf - ref.normal * (Real(0.5) * sep);
    depth[kept] = -sep;
    ids[kept] = base | cur[k].id;
    ++kept;
  }
  if (kept == 0) return 0;
  if (deepest) {
    // A curved feature's polygon (a cylinder cap's 8-gon) can clip away the
    // deepest point: put it back when the clipped points fall short of it.
    Real best = -kInf;
    for (int k = 0; k < kept; ++k) best = std::max(best, depth[k]);
    if (best < deepest->depth - Real(1e-9) * (1 + std::abs(deepest->depth)) && kept < kMaxClipVerts) {
      pos[kept] = deepest->position;
      depth[kept] = deepest->depth;
      ids[kept++] = deepest->feature_id;
    }
  }
  const Vec3 normal = ref_is_b ? Vec3(-ref.normal) : ref.normal;
  int keep[4];
  const int count = reduceToFour(pos, depth, kept, normal, keep);
  m.normal = normal;
  m.count = count;
  for (int k = 0; k < count; ++k) m.points[k] = ContactPoint{pos[keep[k]], depth[keep[k]], ids[keep[k]]};
  return count;
}

bool buildManifold(const ConvexProxy& a, const ConvexProxy& b, const Vec3& n, Real depth, const Vec3& wa,
                   const Vec3& wb, Real margin, Manifold& m) {
  if (depth < -margin) return false;
  Feature fa, fb;
  supportFeature(a, n, fa);
  supportFeature(b, -n, fb);
  const Real cos_a = fa.count >= 3 ? fa.normal.dot(n) : -kInf;
  const Real cos_b = fb.count >= 3 ? -fb.normal.dot(n) : -kInf;
  if (std::max(cos_a, cos_b) >= kFaceCos) {
    const bool ref_is_b = cos_a < kFaceCos;  // A's face whenever it qualifies
    // The witness pair is the deepest contact along n, and n is the face
    // normal here, so it belongs in the face's manifold.
    const ContactPoint witness{Real(0.5) * (wa + wb), depth, pointFeatureId(fa.index, fb.index) | 0x10000000u};
    if (faceContact(ref_is_b ? fb : fa, ref_is_b ? fa : fb, ref_is_b, margin, m, &witness) > 0) return true;
  }
  if (fa.count == 2 && fb.count == 2) {
    // Two segments perpendicular to n (capsule and cylinder sides): if they
    // are parallel, two points over their common extent.
    const Vec3 da = fa.v[1] - fa.v[0], db = fb.v[1] - fb.v[0];
    const Real la = da.norm(), lb = db.norm();
    if (la > 0 && lb > 0 && da.cross(db).norm() < kSegmentSin * la * lb) {
      const Vec3 u = da / la;
      Real t0 = u.dot(fb.v[0] - fa.v[0]) / la, t1 = u.dot(fb.v[1] - fa.v[0]) / la;
      if (t0 > t1) std::swap(t0, t1);
      t0 = std::max(t0, Real(0));
      t1 = std::min(t1, Real(1));
      if (t1 - t0 > Real(1e-6)) {
        int count = 0;
        for (const Real t : {t0, t1}) {
          const Vec3 pa = fa.v[0] + t * da;
          const Vec3 pb = closestOnSegment(pa, fb.v[0], fb.v[1]);
          const Real sep = n.dot(pb - pa) - fa.radius - fb.radius;
          if (sep > margin) continue;
          const Vec3 sa = pa + n * fa.radius, sb = pb - n * fb.radius;
          m.points[count++] = ContactPoint{Real(0.5) * (sa + sb), -sep, pointFeatureId(fa.index, fb.index) | (t == t0 ? 0u : 0x20000000u)};
        }
        if (count > 0) {
          Real best = -kInf;
          for (int k = 0; k < count; ++k) best = std::max(best, m.points[k].depth);
          if (best < depth - Real(1e-9) * (1 + std::abs(depth)))
            m.points[count++] = ContactPoint{Real(0.5) * (wa + wb), depth, pointFeatureId(fa.index, fb.index) | 0x10000000u};
          m.normal = n;
          m.count = count;
          return true;
        }
      }
    }
  }
  m.normal = n;
  m.count = 1;
  m.points[0] = ContactPoint{Real(0.5) * (wa + wb), depth, pointFeatureId(fa.index, fb.index)};
  return true;
}

}  // namespace cairn
