// Closest points between segments (derivation in closest_points.hpp).
#include "collision/closest_points.hpp"

#include <algorithm>

namespace cairn {

Vec3 closestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b, Real* t_out) {
  const Vec3 ab = b - a;
  const Real len2 = ab.squaredNorm();
  Real t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, Real(0), Real(1)) : Real(0);
  if (t_out) *t_out = t;
  return a + t * ab;
}

SegmentPair closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const Real a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  // Zero-length segments are points: the scale of "zero" is the segments'
  // own size, so that millimetre and kilometre shapes behave alike.
  const Real tiny = Real(1e-24) * std::max({a, e, r.squaredNorm(), Real(1e-300)});
  Real s = 0, t = 0;
  if (a <= tiny && e <= tiny) {
    s = t = 0;
  } else if (a <= tiny) {
    t = std::clamp(f / e, Real(0), Real(1));
  } else {
    const Real c = d1.dot(r);
    if (e <= tiny) {
      s = std::clamp(-c / a, Real(0), Real(1));
    } else {
      const Real b = d1.dot(d2);
      const Real denom = a * e - b * b;  // >= 0, zero when parallel
      s = denom > Real(1e-12) * a * e ? std::clamp((b * f - c * e) / denom, Real(0), Real(1)) : Real(0);
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, Real(0), Real(1));
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, Real(0), Real(1));
      }
    }
  }
  return SegmentPair{s, t, p1 + s * d1, p2 + t * d2};
}

}  // namespace cairn
