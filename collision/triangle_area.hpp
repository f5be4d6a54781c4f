// When a triangle has an area, and so a normal a contact can push along.
//
// |(b - a) x (c - a)| is twice the area; compared with the longest edge
// squared it is the triangle's smallest height over its longest edge (up
// to a factor 2). Below 1e-12 the cross product is mostly round-off (its
// error is ~1e-16 of the edge squared), so its direction, the normal, is
// not to be trusted to better than 1e-4: such a sliver is treated as having
// no area, like an exact zero.
#pragma once

#include "cairn/math.hpp"

#include <algorithm>

namespace cairn {

inline bool triangleHasArea(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Real cross = (b - a).cross(c - a).norm();
  const Real longest2 = std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
  return cross > Real(1e-12) * longest2;
}

}  // namespace cairn
