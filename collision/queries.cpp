// Broadphase front end of the queries (contract in queries.hpp).
#include "collision/queries.hpp"

#include "cairn/error.hpp"
#include "collision/aabb.hpp"
#include "collision/overlap.hpp"
#include "collision/shape_cast.hpp"

#include <algorithm>
#include <string>

namespace cairn {
namespace {

void requireFinite(const char* query, const char* field, const Vec3& v) {
  if (!v.allFinite()) throw InputError(query, field, "must be finite");
}

// The pose with its rotation normalized (as the World does for bodies).
Transform checkedQueryShape(const char* query, const ShapeDesc& shape, const Transform& pose) {
  if (!isConvexQueryShape(shape))
    throw InputError(query, "shape",
                     std::string("must be a convex shape (sphere, box, capsule, cylinder, convex_hull), not ") +
                         shapeTypeName(shape.type));
  requireFinite(query, "pose.position", pose.p);
  if (!pose.q.coeffs().allFinite() || pose.q.norm() < Real(1e-9))
    throw InputError(query, "pose.orientation", "must be a finite, non-zero quaternion");
  return Transform{pose.p, pose.q.normalized()};
}

bool hitBefore(const ProxyHit& a, const ProxyHit& b) {
  return a.hit.fraction != b.hit.fraction ? a.hit.fraction < b.hit.fraction : a.user < b.user;
}

// Walks the segment (grown by `extent`) through the broadphase and calls
// cast(shape, pose, max_fraction) on every accepted candidate. Closest:
// keeps the best hit in out[0] and clips the walk at it. All: appends every
// hit, then sorts.
template <class Cast>
void sweep(const BroadPhase& bp, const Vec3& origin, const Vec3& translation, const Vec3& extent, bool closest,
           const ProxyLookup& lookup, const ProxyFilter& filter, Cast&& cast, std::vector<ProxyHit>& out) {
  out.clear();
  bp.rayCast(origin, translation, 1, extent, [&](int handle, Real max_f) -> Real {
    const int user = bp.user(handle);
    if (filter && !filter(user)) return max_f;
    const QueryShape qs = lookup(user);
    if (!qs.shape) return max_f;
    const std::optional<CastHit> h = cast(*qs.shape, qs.pose, max_f);
    if (!h) return max_f;
    const ProxyHit qh{user, *h};
    if (!closest) {
      out.push_back(qh);
      return max_f;
    }
    if (out.empty()) out.push_back(qh);
    else if (hitBefore(qh, out[0])) out[0] = qh;
    return out[0].hit.fraction;
  });
  std::sort(out.begin(), out.end(), hitBefore);
}

void rayCastQuery(const BroadPhase& bp, const Vec3& origin, const Vec3& translation, bool closest,
                  const ProxyLookup& lookup, const ProxyFilter& filter, std::vector<ProxyHit>& out) {
  requireFinite("ray cast", "origin", origin);
  requireFinite("ray cast", "translation", translation);
  out.clear();
  if (translation.squaredNorm() == 0) return;
  sweep(bp, origin, translation, Vec3::Zero(), closest, lookup, filter,
        [&](const ShapeDesc& s, const Transform& t, Real max_f) { return rayCast(s, t, origin, translation, max_f); },
        out);
}

void shapeCastQuery(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose_in, const Vec3& translation,
                    bool closest, const ProxyLookup& lookup, const ProxyFilter& filter, std::vector<ProxyHit>& out) {
  const Transform pose = checkedQueryShape("shape cast", shape, pose_in);
  requireFinite("shape cast", "translation", translation);
  out.clear();
  if (translation.squaredNorm() == 0) return;
  const Aabb box = shapeAabb(shape, pose);
  sweep(bp, box.center(), translation, Real(0.5) * box.extent(), closest, lookup, filter,
        [&](const ShapeDesc& s, const Transform& t, Real max_f) {
          return shapeCast(shape, pose, translation, s, t, max_f);
        },
        out);
}

}  // namespace

std::optional<ProxyHit> rayCastClosest(const BroadPhase& bp, const Vec3& origin, const Vec3& translation,
                                       const ProxyLookup& lookup, const ProxyFilter& filter) {
  std::vector<ProxyHit> out;
  rayCastQuery(bp, origin, translation, true, lookup, filter, out);
  if (out.empty()) return std::nullopt;
  return out[0];
}

std::vector<ProxyHit> rayCastAll(const BroadPhase& bp, const Vec3& origin, const Vec3& translation,
                                 const ProxyLookup& lookup, const ProxyFilter& filter) {
  std::vector<ProxyHit> out;
  rayCastQuery(bp, origin, translation, false, lookup, filter, out);
  return out;
}

std::optional<ProxyHit> shapeCastClosest(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose,
                                         const Vec3& translation, const ProxyLookup& lookup,
                                         const ProxyFilter& filter) {
  std::vector<ProxyHit> out;
  shapeCastQuery(bp, shape, pose, translation, true, lookup, filter, out);
  if (out.empty()) return std::nullopt;
  return out[0];
}

std::vector<ProxyHit> shapeCastAll(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose,
                                   const Vec3& translation, const ProxyLookup& lookup, const ProxyFilter& filter) {
  std::vector<ProxyHit> out;
  shapeCastQuery(bp, shape, pose, translation, false, lookup, filter, out);
  return out;
}

std::vector<int> overlapAll(const BroadPhase& bp, const ShapeDesc& shape, const Transform& pose_in,
                            const ProxyLookup& lookup, const ProxyFilter& filter) {
  const Transform pose = checkedQueryShape("overlap query", shape, pose_in);
  std::vector<int> out;
  bp.query(shapeAabb(shape, pose), [&](int handle) {
    const int user = bp.user(handle);
    if (filter && !filter(user)) return true;
    const QueryShape qs = lookup(user);
    if (qs.shape && overlaps(shape, pose, *qs.shape, qs.pose)) out.push_back(user);
    return true;
  });
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace cairn
