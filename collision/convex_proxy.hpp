// A convex shape placed in the world, as GJK, EPA and the feature clipper see
// it: a support mapping, a core radius and a size for tolerances.
//
// Kinds: Point (sphere core), Segment (capsule core), Box, Cylinder, Hull,
// and Polygon: up to kMaxPolygon world-space points that span a flat convex
// polygon, used for mesh triangles (a triangle is a hull with no thickness).
#pragma once

#include "cairn/shape.hpp"
#include "cairn/math.hpp"

#include <cstdint>

namespace cairn {

struct ConvexProxy {
  enum class Kind : std::uint8_t { Point, Segment, Box, Cylinder, Hull, Polygon };
  static constexpr int kMaxPolygon = 3;

  Kind kind = Kind::Point;
  Vec3 p = Vec3::Zero();        // world position
  Mat3 r = Mat3::Identity();    // world rotation (columns: local axes)
  Vec3 half_extents = Vec3::Zero();
  Real half_height = 0;         // segment, cylinder
  Real cylinder_radius = 0;
  Real radius = 0;              // rounding around the core (sphere, capsule)
  const ConvexHullData* hull = nullptr;
  Vec3 poly[kMaxPolygon];       // Polygon kind: world vertices
  int poly_count = 0;
  Real scale = 1;               // a characteristic length (tolerances)

  // Support point of the core in world direction d.
  Vec3 supportCore(const Vec3& d) const;
  // Support point of the whole shape: the core grown by `radius`.
  Vec3 support(const Vec3& d, bool full) const {
    const Vec3 c = supportCore(d);
    if (!full || radius <= 0) return c;
    const Real len = d.norm();
    return len > 0 ? Vec3(c + d * (radius / len)) : c;
  }
  Vec3 center() const;
};

// Proxy of a convex shape (sphere, box, capsule, cylinder, hull) at world
// transform t.
ConvexProxy makeProxy(const ShapeDesc& s, const Transform& t);
// Proxy of a triangle given by world vertices.
ConvexProxy makeTriangleProxy(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace cairn
