// Box against box: separating axis test and reference-face clipping
// (Gottschalk's OBB test as in Ericson 4.4.1, the contact generation of
// Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013).
//
// With centers c_a, c_b, d = c_b - c_a, rotation columns A_i, B_j and half
// extents a, b, the separation along a unit axis L is
//   sep(L) = |L.d| - sum_i a_i |L.A_i| - sum_j b_j |L.B_j|.
// The 15 candidate axes are A_i, B_j and A_i x B_j (edge pairs; skipped when
// the edges are parallel, as a face axis then covers them). If any sep
// exceeds the margin the boxes are farther apart than we care about.
// Otherwise the largest separation picks the contact:
//   - a face axis: that face is the reference face; the incident face is the
//     other box's face most anti-parallel to it; clipping the incident quad
//     by the reference face's four side planes leaves up to 8 points, of
//     which those within the margin are contacts and the 4 spanning the
//     largest area are kept (contact_features.cpp, clip.cpp).
//   - an edge axis: the two supporting edges, one point at their closest
//     points, depth -sep.
// An edge axis must beat the best face axis by a tolerance (0.1% of the
// smaller box plus 1% of the depth) and B's face must beat A's by a tenth of
// the absolute part: nearly tied axes then choose the same feature every
// frame (at the price of reporting up to 1% too much depth when a face is
// kept against a slightly better edge).
// A feature is used only if it really holds the separation SAT found: the
// clipped incident face keeps a point at that depth (to 1e-5 of the size),
// or the edges' closest points are inside both edges. Otherwise the other
// kind is tried, and failing both (boxes apart with vertices nearest, or
// round-off at a tie) the general GJK / EPA path gives the exact answer.
//
// Feature ids: face contacts 0xRFFIIccc... as in contact_features.hpp
// (reference box and face, incident face, clip vertex code); edge contacts
// 0x4... with the two edge codes (axis * 4 + which parallel edge).
#include "collision/closest_points.hpp"
#include "collision/contact_features.hpp"
#include "collision/narrowphase.hpp"

#include <algorithm>

namespace cairn::narrow {

int boxBox(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out) {
  const Mat3 ra = ta.q.toRotationMatrix(), rb = tb.q.toRotationMatrix();
  const Vec3 ha = a.half_extents, hb = b.half_extents;
  const Vec3 d = tb.p - ta.p;
  const Mat3 c = ra.transpose() * rb;  // c(i, j) = A_i . B_j
  const Mat3 abs_c = c.cwiseAbs();
  const Real size = std::min(ha.minCoeff(), hb.minCoeff());
  const Real tol = Real(1e-3) * size;       // preference between nearly tied axes
  const Real hold_tol = Real(1e-5) * size;  // how much depth a clipped face may miss

  Real sep_a = -kInf, sep_b = -kInf, sep_e = -kInf;
  int axis_a = 0, axis_b = 0, edge_i = -1, edge_j = -1;
  Vec3 edge_l = Vec3::Zero();
  const Vec3 da = ra.transpose() * d, db = rb.transpose() * d;
  for (int i = 0; i < 3; ++i) {
    const Real s = std::abs(da[i]) - ha[i] - hb.dot(abs_c.row(i).transpose());
    if (s > sep_a) sep_a = s, axis_a = i;
  }
  for (int j = 0; j < 3; ++j) {
    const Real s = std::abs(db[j]) - hb[j] - ha.dot(abs_c.col(j));
    if (s > sep_b) sep_b = s, axis_b = j;
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Vec3 l = ra.col(i).cross(rb.col(j));
      const Real len = l.norm();
      if (len < Real(1e-6)) continue;
      l /= len;
      const Real s = std::abs(l.dot(d)) - ha.dot((ra.transpose() * l).cwiseAbs()) - hb.dot((rb.transpose() * l).cwiseAbs());
      if (s > sep_e) sep_e = s, edge_i = i, edge_j = j, edge_l = l.dot(d) < 0 ? Vec3(-l) : l;
    }
  }
  if (std::max({sep_a, sep_b, sep_e}) > margin) return 0;

  Manifold m;
  const Real face_sep = std::max(sep_a, sep_b);

  // Edge contact: A's edge along A_i on the side of +L, B's along B_j on the
  // side of -L; valid when their closest points are inside both edges.
  auto edgeContact = [&]() {
    if (edge_i < 0) return false;
    auto edge = [](const Vec3& center, const Mat3& r, const Vec3& h, int axis, const Vec3& dir, Vec3& e0, Vec3& e1, int& code) {
      Vec3 mid = center;
      int bits = 0;
      for (int k = 0; k < 3; ++k) {
        if (k == axis) continue;
        const Real s = r.col(k).dot(dir) < 0 ? Real(-1) : Real(1);
        mid += r.col(k) * (s * h[k]);
        bits = bits * 2 + (s > 0 ? 1 : 0);
      }
      e0 = mid - r.col(axis) * h[axis];
      e1 = mid + r.col(axis) * h[axis];
      code = axis * 4 + bits;
    };
    Vec3 a0, a1, b0, b1;
    int code_a, code_b;
    edge(ta.p, ra, ha, edge_i, edge_l, a0, a1, code_a);
    edge(tb.p, rb, hb, edge_j, -edge_l, b0, b1, code_b);
    const SegmentPair cp = closestSegmentSegment(a0, a1, b0, b1);
    if (!(cp.s > 0 && cp.s < 1 && cp.t > 0 && cp.t < 1)) return false;
    m.normal = edge_l;
    m.count = 1;
    m.points[0] = ContactPoint{Real(0.5) * (cp.p + cp.q), -sep_e, pointFeatureId(code_a, code_b)};
    return true;
  };

  // Face contact: the reference face, the most anti-parallel incident face,
  // clipping; valid when the clipped face still holds SAT's depth.
  auto faceContactOf = [&]() {
    const bool ref_is_b = sep_b > sep_a + Real(0.1) * tol;
    Feature ref, inc;
    if (!ref_is_b) {
      const int i = axis_a;
      const Real s = da[i] < 0 ? Real(-1) : Real(1);  // A's face toward B
      boxFace(ta.p, ra, ha, 2 * i + (s < 0 ? 1 : 0), ref);
      const Vec3 nl = rb.transpose() * ref.normal;
      int j = 0;
      nl.cwiseAbs().maxCoeff(&j);
      boxFace(tb.p, rb, hb, 2 * j + (nl[j] > 0 ? 1 : 0), inc);
    } else {
      const int j = axis_b;
      const Real s = db[j] > 0 ? Real(-1) : Real(1);  // B's face toward A
      boxFace(tb.p, rb, hb, 2 * j + (s < 0 ? 1 : 0), ref);
      const Vec3 nl = ra.transpose() * ref.normal;
      int i = 0;
      nl.cwiseAbs().maxCoeff(&i);
      boxFace(ta.p, ra, ha, 2 * i + (nl[i] > 0 ? 1 : 0), inc);
    }
    m.count = 0;
    if (faceContact(ref, inc, ref_is_b, margin, m) == 0) return false;
    Real deepest = -kInf;
    for (int k = 0; k < m.count; ++k) deepest = std::max(deepest, m.points[k].depth);
    return deepest >= -face_sep - hold_tol;
  };

  const bool prefer_edge = edge_i >= 0 && sep_e > face_sep + tol + Real(0.01) * std::abs(face_sep);
  const bool ok = prefer_edge ? (edgeContact() || faceContactOf()) : (faceContactOf() || edgeContact());
  if (!ok) return convexConvex(a, ta, b, tb, margin, out);
  out.push_back(m);
  return 1;
}

}  // namespace cairn::narrow
