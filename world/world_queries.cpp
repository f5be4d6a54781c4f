// The World's geometric queries (include/cairn/query.hpp): ray casts, shape
// casts and overlap tests against every shape in the world, through the
// broadphase front end of collision/queries.hpp.
//
// The broadphase proxies' user ints are the world's shape slots, so the
// lookup is one array read: the shape and its pose now (body transform times
// ShapeDesc::local). Every proxy's fat box holds its shape's current box
// (world/world_contacts.cpp moves the proxies again after the positions
// move, and setTransform moves a teleported body's), so the broadphase never
// hides a shape from a query. Results carry handles: the body, and the
// shape's slot with its generation.
#include "collision/queries.hpp"

#include "cairn/error.hpp"
#include "collision/shape_cast.hpp"
#include "world/world_impl.hpp"

namespace cairn::detail {

namespace {

ProxyLookup lookupOf(const WorldImpl& w) {
  return [&w](int slot) {
    const ShapeRef& ref = w.shapes()[static_cast<size_t>(slot)];
    const Body& b = w.body(ref.body);
    const ShapeDesc& s = b.shapes[static_cast<size_t>(ref.index)];
    return QueryShape{&s, b.transform() * s.local};
  };
}

bool typeWanted(const QueryFilter& f, BodyType t) {
  switch (t) {
    case BodyType::Static: return f.static_bodies;
    case BodyType::Kinematic: return f.kinematic_bodies;
    case BodyType::Dynamic: return f.dynamic_bodies;
  }
  return false;
}

ProxyFilter filterOf(const WorldImpl& w, const QueryFilter& f) {
  return [&w, &f](int slot) {
    const ShapeRef& ref = w.shapes()[static_cast<size_t>(slot)];
    const Body& b = w.body(ref.body);
    if (!typeWanted(f, b.type)) return false;
    // The body-pair rule of World::setCollisionFilter, the query playing a body.
    if ((b.collision_group & f.mask) == 0 || (f.group & b.collision_mask) == 0) return false;
    if (!f.ignore.isWorld() && ref.body == f.ignore) return false;
    return !f.accept || f.accept(ref.body, ShapeId{slot, ref.generation});
  };
}

template <class Hit>
Hit toHit(const WorldImpl& w, const ProxyHit& h) {
  const ShapeRef& ref = w.shapes()[static_cast<size_t>(h.user)];
  Hit out;
  out.body = ref.body;
  out.shape = ShapeId{h.user, ref.generation};
  out.fraction = h.hit.fraction;
  out.point = h.hit.point;
  out.normal = h.hit.normal;
  out.triangle = h.hit.triangle;
  return out;
}

// The query shape's own fields, as a body's shape would be checked (a
// negative radius would sweep nonsense rather than fail).
void checkQueryShape(const char* query, const ShapeDesc& shape) {
  if (!isConvexQueryShape(shape))
    throw InputError(query, "shape",
                     std::string("must be a convex shape (sphere, box, capsule, cylinder, convex_hull), not ") +
                         shapeTypeName(shape.type));
  validateShape(query, "shape", shape, BodyType::Dynamic);
}

}  // namespace

std::optional<RayHit> WorldImpl::castRay(const Vec3& origin, const Vec3& translation, const QueryFilter& f) const {
  const auto h = rayCastClosest(broadphase_, origin, translation, lookupOf(*this), filterOf(*this, f));
  if (!h) return std::nullopt;
  return toHit<RayHit>(*this, *h);
}

std::vector<RayHit> WorldImpl::castRayAll(const Vec3& origin, const Vec3& translation, const QueryFilter& f) const {
  std::vector<RayHit> out;
  for (const ProxyHit& h : rayCastAll(broadphase_, origin, translation, lookupOf(*this), filterOf(*this, f)))
    out.push_back(toHit<RayHit>(*this, h));
  return out;
}

std::optional<ShapeCastHit> WorldImpl::castShape(const ShapeDesc& shape, const Transform& pose, const Vec3& translation,
                                                 const QueryFilter& f) const {
  checkQueryShape("shape cast", shape);
  const auto h = shapeCastClosest(broadphase_, shape, pose, translation, lookupOf(*this), filterOf(*this, f));
  if (!h) return std::nullopt;
  return toHit<ShapeCastHit>(*this, *h);
}

std::vector<ShapeId> WorldImpl::overlap(const ShapeDesc& shape, const Transform& pose, const QueryFilter& f) const {
  checkQueryShape("overlap query", shape);
  std::vector<ShapeId> out;
  for (const int slot : overlapAll(broadphase_, shape, pose, lookupOf(*this), filterOf(*this, f)))
    out.push_back(ShapeId{slot, shapes_[static_cast<size_t>(slot)].generation});
  return out;
}

}  // namespace cairn::detail

namespace cairn {

std::optional<RayHit> World::castRay(const Vec3& origin, const Vec3& translation, const QueryFilter& filter) const {
  return impl_->castRay(origin, translation, filter);
}

std::vector<RayHit> World::castRayAll(const Vec3& origin, const Vec3& translation, const QueryFilter& filter) const {
  return impl_->castRayAll(origin, translation, filter);
}

std::optional<ShapeCastHit> World::castShape(const ShapeDesc& shape, const Transform& pose, const Vec3& translation,
                                             const QueryFilter& filter) const {
  return impl_->castShape(shape, pose, translation, filter);
}

std::vector<ShapeId> World::overlap(const ShapeDesc& shape, const Transform& pose, const QueryFilter& filter) const {
  return impl_->overlap(shape, pose, filter);
}

}  // namespace cairn
