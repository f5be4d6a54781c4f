// Axis-aligned bounding boxes: the broadphase's unit of overlap, and the
// world bounds of every shape.
//
// Bounds of a shape with rotation R at position p:
//   box       p +- |R| h                        (|R| = entrywise absolute value)
//   sphere    p +- r
//   capsule   p +- (|R e_y| hh + r)
//   cylinder  per world axis i, with unit axis a = R e_y:
//             p_i +- (hh |a_i| + r sqrt(1 - a_i^2))
//             (the disc of radius r perpendicular to a reaches
//              r sqrt(1 - a_i^2) along world axis i)
//   hull, mesh  the box of the transformed vertices (exact)
//   plane     a half-space n.x <= d is unbounded: the box is infinite along
//             every axis, except that an axis-aligned plane bounds its own
//             axis on one side. isInfinite() says so, and the broadphase
//             keeps such shapes out of its tree.
#pragma once

#include "cairn/shape.hpp"
#include "cairn/math.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cairn {

struct Aabb {
  // Default: the empty box (lo > hi), which grow() and merge() start from.
  Vec3 lo = Vec3::Constant(kInf);
  Vec3 hi = Vec3::Constant(-kInf);

  static Aabb fromCenterHalf(const Vec3& c, const Vec3& half) { return Aabb{c - half, c + half}; }

  bool empty() const { return (lo.array() > hi.array()).any(); }
  bool isInfinite() const { return !lo.allFinite() || !hi.allFinite(); }
  // Closed intervals: boxes that touch overlap (a resting contact has a gap
  // of exactly zero and must still be found).
  bool overlaps(const Aabb& o) const {
    return lo.x() <= o.hi.x() && o.lo.x() <= hi.x() && lo.y() <= o.hi.y() && o.lo.y() <= hi.y() &&
           lo.z() <= o.hi.z() && o.lo.z() <= hi.z();
  }
  bool contains(const Aabb& o) const { return (lo.array() <= o.lo.array()).all() && (o.hi.array() <= hi.array()).all(); }
  bool contains(const Vec3& p) const { return (lo.array() <= p.array()).all() && (p.array() <= hi.array()).all(); }
  void grow(const Vec3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Aabb merged(const Aabb& o) const { return Aabb{lo.cwiseMin(o.lo), hi.cwiseMax(o.hi)}; }
  Aabb expanded(Real margin) const { return Aabb{lo.array() - margin, hi.array() + margin}; }
  Vec3 center() const { return Real(0.5) * (lo + hi); }
  Vec3 extent() const { return hi - lo; }
  // Surface area, the cost the tree's insertion heuristic minimizes (the
  // probability that a random ray or box hits a box is proportional to it).
  Real surfaceArea() const {
    const Vec3 e = hi - lo;
    return Real(2) * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
  }
};

// Slab test (Kay and Kajiya, "Ray Tracing Complex Scenes", SIGGRAPH 1986):
// clips the parameter interval [t0, t1] of the line o + t d to the box
// [lo, hi]; false when the interval becomes empty. Per axis the line is
// between the two slab planes for t between (lo_i - o_i) / d_i and
// (hi_i - o_i) / d_i; `inv_d` is 1 / d componentwise, and a non-finite
// component (d_i = 0) keeps the interval when lo_i <= o_i <= hi_i and
// empties it otherwise (closed slabs: a line along a face touches the box).
// enter_axis (optional) receives the axis whose near plane last raised t0,
// left alone when none did.
inline bool clipLineToBox(const Vec3& lo, const Vec3& hi, const Vec3& o, const Vec3& inv_d, Real& t0, Real& t1,
                          int* enter_axis = nullptr) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(inv_d[i])) {
      if (o[i] < lo[i] || o[i] > hi[i]) return false;
      continue;
    }
    // min / max rather than branches: which plane is near and whether it
    // clips are coin flips for a tree walk's random boxes.
    const Real ta = (lo[i] - o[i]) * inv_d[i], tb = (hi[i] - o[i]) * inv_d[i];
    const Real near = std::min(ta, tb), far = std::max(ta, tb);
    if (enter_axis && near > t0) *enter_axis = i;
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
  }
  return t0 <= t1;
}

// A node waiting on a segment query's stack, with the fraction at which the
// segment enters its box.
struct SegmentEntry {
  int node;
  Real enter;
};

// Pushes two children met by a segment, the farther first so that the nearer
// is popped (and can clip the segment) first; a child entered beyond
// max_fraction is dropped. On a tie `a` counts as the nearer.
inline void pushNearerLast(SegmentEntry* stack, int& top, SegmentEntry a, SegmentEntry b, Real max_fraction) {
  if (b.enter < a.enter) std::swap(a, b);
  if (b.enter <= max_fraction) stack[top++] = b;
  if (a.enter <= max_fraction) stack[top++] = a;
}

// World bounds of `shape` placed at `t` (t already includes shape.local).
Aabb shapeAabb(const ShapeDesc& shape, const Transform& t);
// World bounds of `shape` on a body at `body`: shapeAabb at body *
// shape.local, to the bit, without composing the rotations where the box
// does not depend on them (a sphere's is its centre's).
Aabb bodyShapeAabb(const ShapeDesc& shape, const Transform& body);

inline Aabb triangleAabb(const Vec3& a, const Vec3& b, const Vec3& c) {
  return Aabb{a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)};
}

}  // namespace cairn
