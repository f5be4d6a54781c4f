// The per-pair routines behind collide() (manifold.hpp). Each takes its two
// shapes in the order its name gives and reports normals from the first
// toward the second; collide() swaps and flips for the other order.
#pragma once

#include "collision/convex_proxy.hpp"
#include "collision/manifold.hpp"

#include <vector>

namespace cairn::narrow {

using Out = std::vector<Manifold>;

int sphereSphere(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
int sphereCapsule(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
int sphereBox(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
int capsuleCapsule(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
int capsuleBox(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
int boxBox(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
// Plane first; b is any convex shape.
int planeConvex(const ShapeDesc& plane, const Transform& tp, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
// Any two convex shapes, by GJK / EPA and feature clipping.
int convexConvex(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);
// Mesh first; b is any convex shape.
int meshConvex(const ShapeDesc& mesh, const Transform& tm, const ShapeDesc& b, const Transform& tb, Real margin, Out& out);

// Normal (unit, from A toward B), depth (> 0 penetrating, < 0 apart) and the
// two surface points of two convex proxies, by GJK on the cores or EPA
// (collide_convex.cpp). False when farther apart than margin.
struct Separation {
  Vec3 normal = Vec3::UnitY();
  Real depth = 0;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();
};
bool convexSeparation(const ConvexProxy& a, const ConvexProxy& b, Real margin, Separation& out);

// The GJK / EPA path on proxies (also used for mesh triangles and as the
// fallback of the dedicated routines). False when farther than margin.
bool convexProxies(const ConvexProxy& a, const ConvexProxy& b, Real margin, Manifold& m);

}  // namespace cairn::narrow
