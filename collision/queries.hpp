// World queries over the broadphase: ray casts, shape casts and overlap tests
// against every shape with a proxy in a BroadPhase (Box2D's b2World_CastRay
// and b2World_OverlapShape, Jolt's NarrowPhaseQuery, Bullet's rayTest,
// convexSweepTest and contactTest).
//
// The broadphase knows only boxes and user ints; the caller says what shape
// a user int stands for through `lookup` (user -> shape and world pose, the
// pose including ShapeDesc::local) and which to consider through `filter`
// (user -> accept; empty accepts all). Each candidate whose fat box the
// segment (or the moving shape's swept box, or the query shape's box) meets
// is tested exactly by ray_cast.hpp, shape_cast.hpp or overlap.hpp; their
// conventions (fractions of the translation, outward normals, starts inside
// at fraction 0) carry over unchanged.
//
// Closest queries walk the tree nearest node first and clip the segment at
// every hit, so nodes beyond the best hit so far are never opened. Every
// shape is reported at most once (a mesh by its first triangle hit). Ties go
// to the lowest user int, and lists are sorted (hits by fraction, then user;
// overlaps by user), so the results do not depend on the tree's shape.
//
// Bad input (a non-finite origin, translation or pose, a query shape that is
// not convex) throws InputError naming the query and the field.
#pragma once

#include "collision/broadphase.hpp"
#include "collision/ray_cast.hpp"

#include <functional>
#include <optional>
#include <vector>

namespace cairn {

struct QueryShape {
  const ShapeDesc* shape = nullptr;  // nullptr: skip this proxy
  Transform pose;                    // world pose of the shape (body * local)
};
using ProxyLookup = std::function<QueryShape(int user)>;
using ProxyFilter = std::function<bool(int user)>;

struct ProxyHit {
  int user = -1;  // the proxy's user int
  CastHit hit;
};

// Segment [origin, origin + translation].
std::optional<ProxyHit> rayCastClosest(const BroadPhase& bp, const Vec3& origin, const Vec3& translation,
                                       const ProxyLookup& lookup, const ProxyFilter& filter = {});
std::vector<ProxyHit> rayCastAll(const BroadPhase& bp, const Vec3& origin, const Vec3& translation,
                                 const ProxyLookup& lookup, const ProxyFilter& filter = {});

// `shape` (convex) at `pose` swept by `translation`.
std::optional<ProxyHit> shapeCastClosest(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose,
                                         const Vec3& translation, const ProxyLookup& lookup,
                                         const ProxyFilter& filter = {});
std::vector<ProxyHit> shapeCastAll(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose,
                                   const Vec3& translation, const ProxyLookup& lookup, const ProxyFilter& filter = {});

// Users whose shapes `shape` (convex) at `pose` overlaps (touching counts),
// ascending.
std::vector<int> overlapAll(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose,
                            const ProxyLookup& lookup, const ProxyFilter& filter = {});

}  // namespace cairn
