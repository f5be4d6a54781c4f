// Capsule against capsule and against box.
//
// Capsule-capsule: the closest points p, q of the two segments (Ericson
// 5.1.9) give n = (q - p) / |q - p| and depth = r_a + r_b - |q - p|. When the
// segments are parallel to within 2 degrees, B's segment is clipped to A's
// extent and each end of the common stretch is a contact, so a capsule lying
// on a capsule is held at two points. Segments that intersect have no
// closest-point direction: the normal is then a x b (their common
// perpendicular), or any perpendicular of a when they are also parallel.
//
// Capsule-box, in the box frame with segment p(t) = p0 + t u: the separating
// axes of a segment and a box are the box's face normals e_i and u x e_i
// (the faces of the Minkowski sum box (+) segment). For each axis L the
// separation is the gap between the projections minus the radius,
//   sep(L) = max(min_t L.p(t) - h_L, -h_L - max_t L.p(t)) - r,
//   h_L = sum_j h_j |L_j|.
// The largest sep is the penetration (exact when negative: SAT is exact for
// polytopes, and the radius just offsets every support distance). A face
// axis wins ties against edge axes by a tolerance (0.1% of the size plus 1%
// of the depth), so a capsule lying on a face is a face contact.
//
// Face contact: the segment is clipped to the face rectangle. A capsule
// lying flat on the face (axis within 2 degrees of it) gets both ends of the
// clipped part as contacts, each the lowest point q - r n of the sphere
// around the segment point q (off the true surface by at most
// r (1 - cos 2 deg) = 6e-4 r); a tilted one only its lower end, where that
// is exact. The face result is trusted only when the clipped segment still
// holds the depth SAT found (to within 1e-5 of the size): otherwise the
// capsule reaches past the face's rim.
// Edge contact: one point at the closest points of the segment and the box
// edge, trusted only when they are inside both (else the edge pair is not
// what touches, e.g. apart, where SAT's separation is only a lower bound of
// the distance). Failing both, the general GJK / EPA path answers.
#include "collision/closest_points.hpp"
#include "collision/contact_features.hpp"
#include "collision/narrowphase.hpp"

#include <algorithm>

namespace cairn::narrow {

int capsuleCapsule(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  const Vec3 ua = ta.q * Vec3::UnitY(), ub = tb.q * Vec3::UnitY();
  const Vec3 a0 = ta.p - ua * a.half_height, a1 = ta.p + ua * a.half_height;
  const Vec3 b0 = tb.p - ub * b.half_height, b1 = tb.p + ub * b.half_height;
  const Real ra = a.radius, rb = b.radius;
  const SegmentPair cp = closestSegmentSegment(a0, a1, b0, b1);
  const Vec3 d = cp.q - cp.p;
  const Real dist = d.norm();
  if (dist - ra - rb > margin) return 0;
  const Real scale = ra + rb + a.half_height + b.half_height;
  Vec3 n;
  if (dist > Real(1e-12) * scale) {
    n = d / dist;
  } else {
    const Vec3 c = ua.cross(ub);
    n = c.norm() > Real(1e-6) ? Vec3(c.normalized()) : anyPerpendicular(ua);
    if (n.dot(tb.p - ta.p) < 0) n = -n;
  }
  Manifold m;
  m.normal = n;
  if (ua.cross(ub).norm() < Real(0.0349) && a.half_height > 0) {
    // Parallel: the common stretch, in A's segment parameter.
    Real t0 = ua.dot(b0 - a0) / (2 * a.half_height), t1 = ua.dot(b1 - a0) / (2 * a.half_height);
    if (t0 > t1) std::swap(t0, t1);
    t0 = std::max(t0, Real(0));
    t1 = std::min(t1, Real(1));
    if (t1 - t0 > Real(1e-6)) {
      for (int k = 0; k < 2; ++k) {
        const Vec3 pa = a0 + (k ? t1 : t0) * (a1 - a0);
        const Vec3 qb = closestOnSegment(pa, b0, b1);
        const Real sep = n.dot(qb - pa) - ra - rb;
        if (sep > margin) continue;
        m.points[m.count++] = ContactPoint{Real(0.5) * ((pa + n * ra) + (qb - n * rb)), -sep, static_cast<std::uint32_t>(k)};
      }
    }
  }
  if (m.count == 0) {
    m.count = 1;
    m.points[0] = ContactPoint{Real(0.5) * ((cp.p + n * ra) + (cp.q - n * rb)), ra + rb - dist, 2};
  }
  out.push_back(m);
  return 1;
}

int capsuleBox(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  const Vec3 h = b.half_extents;
  const Real r = a.radius;
  const Quat q_rel = tb.q.conjugate() * ta.q;
  const Vec3 axis = q_rel * Vec3::UnitY();
  const Vec3 center = tb.applyInverse(ta.p);
  const Vec3 p0 = center - axis * a.half_height, p1 = center + axis * a.half_height;
  const Vec3 u = p1 - p0;
  const Real scale = std::min(h.minCoeff(), r + a.half_height);
  const Real tol = Real(1e-3) * scale;       // preference between nearly tied axes
  const Real hold_tol = Real(1e-5) * scale;  // how much depth a clipped face may miss

  // Separating axis test.
  Real face_sep = -kInf, edge_sep = -kInf;
  int face_axis = 0, edge_axis = -1;
  Real face_sign = 1;
  Vec3 edge_l = Vec3::Zero();
  for (int i = 0; i < 3; ++i) {
    const Real lo = std::min(p0[i], p1[i]), hi = std::max(p0[i], p1[i]);
    const Real plus = lo - h[i], minus = -h[i] - hi;
    const Real sep = std::max(plus, minus) - r;
    if (sep > face_sep) face_sep = sep, face_axis = i, face_sign = plus >= minus ? 1 : -1;
  }
  const Real ulen = u.norm();
  for (int i = 0; i < 3 && ulen > 0; ++i) {
    Vec3 l = u.cross(Vec3::Unit(i));
    const Real len = l.norm();
    if (len < Real(1e-6) * ulen) continue;  // u parallel to e_i: a face axis covers it
    l /= len;
    const Real hl = h.dot(l.cwiseAbs());
    const Real s0 = l.dot(p0);  // = l.p1: l is perpendicular to u
    const Real plus = s0 - hl, minus = -hl - s0;
    const Real sep = std::max(plus, minus) - r;
    if (sep > edge_sep) edge_sep = sep, edge_axis = i, edge_l = plus >= minus ? l : Vec3(-l);
  }
  if (std::max(face_sep, edge_sep) > margin) return 0;

  Manifold m;
  auto edgeContact = [&]() {
    if (edge_axis < 0) return false;
    // Edge contact: the box edge parallel to e_i on the side of L.
    const int i = edge_axis;
    Vec3 c = Vec3::Zero();
    int bits = 0;
    for (int j = 0; j < 3; ++j) {
      if (j == i) continue;
      const Real s = edge_l[j] < 0 ? Real(-1) : Real(1);
      c[j] = s * h[j];
      bits = bits * 2 + (s > 0 ? 1 : 0);
    }
    const SegmentPair cp = closestSegmentSegment(p0, p1, c - Vec3::Unit(i) * h[i], c + Vec3::Unit(i) * h[i]);
    if (!(cp.s > 0 && cp.s < 1 && cp.t > 0 && cp.t < 1)) return false;
    const Vec3 capsule_point = tb.apply(cp.p - edge_l * r);
    m.normal = tb.q * (-edge_l);  // capsule toward box
    m.count = 1;
    m.points[0] = ContactPoint{Real(0.5) * (capsule_point + tb.apply(cp.q)), -edge_sep,
                               0x100u | static_cast<std::uint32_t>(i * 4 + bits)};
    return true;
  };
  auto faceContact = [&]() {
    m.count = 0;
    // Face contact: clip the segment to the face rectangle.
    const int i = face_axis;
    const Real s = face_sign;
    Real t0 = 0, t1 = 1;
    std::uint32_t id0 = 0, id1 = 1;  // endpoint 0 / 1, or 0x10 + clipping side
    bool hit = true;
    for (int j = 0; j < 3 && hit; ++j) {
      if (j == i) continue;
      for (int side = 0; side < 2 && hit; ++side) {
        // Keep sg * x_j <= h_j along the segment.
        const Real sg = side ? Real(-1) : Real(1);
        const Real f0 = sg * p0[j] - h[j], du = sg * u[j];
        if (du == 0) {
          if (f0 > 0) hit = false;
          continue;
        }
        const Real t = -f0 / du;
        const std::uint32_t id = 0x10u + static_cast<std::uint32_t>(2 * j + side);
        if (du > 0) {
          if (t < t1) t1 = t, id1 = id;
        } else {
          if (t > t0) t0 = t, id0 = id;
        }
        if (t0 > t1) hit = false;
      }
    }
    if (hit) {
      const Vec3 nf = Vec3::Unit(i) * s;  // box face normal, toward the capsule
      const std::uint32_t face = static_cast<std::uint32_t>(2 * i + (s < 0 ? 1 : 0)) << 8;
      // Lying flat on the face (within 2 degrees): both ends of the clipped
      // part. Tilted: only the lower end, which must have survived the clip.
      const bool flat = std::abs(nf.dot(u)) < kSegmentSin * ulen;
      Real ts[2];
      std::uint32_t ids[2];
      int nt = 0;
      if (flat) {
        ts[nt] = t0, ids[nt++] = id0;
        if (t1 - t0 > Real(1e-9)) ts[nt] = t1, ids[nt++] = id1;
      } else {
        const Real t_low = nf.dot(u) < 0 ? Real(1) : Real(0);
        if (t_low >= t0 && t_low <= t1) ts[nt] = t_low, ids[nt++] = t_low > 0 ? 1u : 0u;
      }
      Real deepest = -kInf;
      for (int k = 0; k < nt; ++k) {
        const Vec3 qk = p0 + ts[k] * u;
        const Vec3 capsule_point = qk - nf * r;  // the lowest point of the sphere around qk
        const Real sep = nf.dot(capsule_point) - h[i];
        deepest = std::max(deepest, -sep);
        if (sep > margin) continue;
        const Vec3 box_point = capsule_point - nf * sep;
        m.points[m.count++] = ContactPoint{tb.apply(Real(0.5) * (capsule_point + box_point)), -sep, face | ids[k]};
      }
      m.normal = tb.q * (-nf);
      // The face must really hold the segment's deepest point (to within
      // hold_tol): if the clip cut it away, the capsule reaches past the face's
      // rim and the nearest features are elsewhere.
      return m.count > 0 && deepest >= -face_sep - hold_tol;
    }
    return false;
  };
  const bool prefer_edge = edge_axis >= 0 && edge_sep > face_sep + tol + Real(0.01) * std::abs(face_sep);
  const bool ok = prefer_edge ? (edgeContact() || faceContact()) : (faceContact() || edgeContact());
  if (!ok) return convexConvex(a, ta, b, tb, margin, out);
  out.push_back(m);
  return 1;
}

}  // namespace cairn::narrow
