// Closest points between simple primitives (Ericson, "Real-Time Collision
// Detection", 2005, section 5.1).
//
// Segment-segment: points P(s) = p1 + s d1, Q(t) = p2 + t d2, s, t in [0, 1].
// Minimizing |P(s) - Q(t)|^2 gives the 2x2 system
//   [ a  -b ] [s]   [-c]      a = d1.d1, b = d1.d2, e = d2.d2,
//   [ b  -e ] [t] = [-f]      r = p1 - p2, c = d1.r, f = d2.r,
// whose solution s = (b f - c e) / (a e - b^2) is clamped to [0, 1]; then t
// is recomputed for that s, clamped, and s recomputed for the clamped t.
// Parallel segments (a e - b^2 ~ 0) take s = 0 and continue the same way.
#pragma once

#include "cairn/math.hpp"

namespace cairn {

// Point on segment [a, b] nearest to p; *t receives its parameter.
Vec3 closestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b, Real* t = nullptr);

struct SegmentPair {
  Real s, t;    // parameters on the first and second segment
  Vec3 p, q;    // the closest points
};
SegmentPair closestSegmentSegment(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2);

}  // namespace cairn
