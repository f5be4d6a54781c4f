// cairn shapes as Bullet collision shapes.
//
// Bullet's convex shapes carry a collision margin (0.04 m by default):
//   sphere, capsule   the margin is the radius itself: exact.
//   box, cylinder     the margin lies inside the given size (Bullet shrinks
//                     the core and adds the margin back): the outer size is
//                     exact, edges and corners are rounded with r = 0.04.
//                     A box or cylinder thinner than 0.16 m gets a smaller
//                     margin (a quarter of its smallest half size) so that
//                     the rounding stays small beside it; with
//                     MarginRule::BulletDefault only one thinner than
//                     0.08 m does, whose core would otherwise invert.
//   convex hull       Bullet adds the margin outside the points, so the hull
//                     is first shrunk by the margin (btConvexHullComputer moves
//                     every face inward); shrunk core + margin = the hull with
//                     rounded edges. A thin hull shrinks less, and its margin
//                     is what it shrank.
//   plane, mesh       no margin (btConcaveShape's default 0). Bullet's
//                     triangle meshes are two-sided; cairn's push out along
//                     the counter-clockwise normal only.
#include "validation/bullet_internal.hpp"

#include <BulletCollision/CollisionShapes/btTriangleMesh.h>
#include <LinearMath/btConvexHullComputer.h>

#include <algorithm>
#include <cmath>

namespace cairn::validation::detail {

namespace {

constexpr Real kDefaultMargin = Real(0.04);  // CONVEX_DISTANCE_MARGIN

// Keeps the margin inside thin boxes and cylinders.
Real insideMargin(Real smallest_half_size, MarginRule rule, std::vector<std::string>& notes, const std::string& who) {
  if (rule == MarginRule::Thin || smallest_half_size >= kDefaultMargin)
    return rule == MarginRule::Thin ? std::min(kDefaultMargin, Real(0.25) * smallest_half_size) : kDefaultMargin;
  notes.push_back(who + ": thinner than Bullet's default margin allows (0.08 m); margin a quarter of its smallest "
                        "half size instead of 0.04 m");
  return Real(0.25) * smallest_half_size;
}

btCollisionShape* makeHull(const ConvexHullData& hull, ShapeStore& store, std::vector<std::string>& notes,
                           const std::string& who) {
  std::vector<double> coords;
  coords.reserve(hull.vertices.size() * 3);
  for (const Vec3& v : hull.vertices) coords.insert(coords.end(), {v.x(), v.y(), v.z()});
  btConvexHullComputer computer;
  const btScalar shrunk = computer.compute(coords.data(), 3 * static_cast<int>(sizeof(double)),
                                           static_cast<int>(hull.vertices.size()), kDefaultMargin, Real(0.5));
  if (shrunk < 0 || computer.vertices.size() < 4) {
    // Bullet could not shrink it: keep the points and a zero margin.
    auto* shape = store.make<btConvexHullShape>();
    for (const Vec3& v : hull.vertices) shape->addPoint(toBt(v), false);
    shape->recalcLocalAabb();
    shape->setMargin(0);
    notes.push_back(who + ": convex hull kept with zero collision margin (Bullet could not shrink it)");
    return shape;
  }
  auto* shape = store.make<btConvexHullShape>();
  for (int i = 0; i < computer.vertices.size(); ++i) shape->addPoint(computer.vertices[i], false);
  shape->recalcLocalAabb();
  shape->setMargin(shrunk);
  return shape;
}

}  // namespace

btCollisionShape* makeShape(const ShapeDesc& s, ShapeStore& store, std::vector<std::string>& notes,
                            const std::string& who, MarginRule margins) {
  switch (s.type) {
    case ShapeType::Sphere:
      return store.make<btSphereShape>(s.radius);
    case ShapeType::Box: {
      auto* box = store.make<btBoxShape>(toBt(s.half_extents));
      const Real m = insideMargin(s.half_extents.minCoeff(), margins, notes, who);
      if (m != kDefaultMargin) box->setMargin(m);  // setMargin keeps the outer size
      return box;
    }
    case ShapeType::Capsule:
      if (s.half_height <= 0) return store.make<btSphereShape>(s.radius);
      return store.make<btCapsuleShape>(s.radius, 2 * s.half_height);  // along y
    case ShapeType::Cylinder: {
      auto* cyl = store.make<btCylinderShape>(btVector3(s.radius, s.half_height, s.radius));  // along y
      const Real m = insideMargin(std::min(s.radius, s.half_height), margins, notes, who);
      if (m != kDefaultMargin) cyl->setMargin(m);
      return cyl;
    }
    case ShapeType::Plane: {
      const Real n = s.normal.norm();
      return store.make<btStaticPlaneShape>(toBt(s.normal / n), s.offset / n);
    }
    case ShapeType::ConvexHull:
      return makeHull(*s.hull, store, notes, who);
    case ShapeType::Mesh: {
      auto mesh = std::make_unique<btTriangleMesh>();
      const auto& m = *s.mesh;
      for (const auto& t : m.triangles)
        mesh->addTriangle(toBt(m.vertices[static_cast<size_t>(t[0])]), toBt(m.vertices[static_cast<size_t>(t[1])]),
                          toBt(m.vertices[static_cast<size_t>(t[2])]));
      btTriangleMesh* raw = mesh.get();
      store.meshes.push_back(std::move(mesh));
      return store.make<btBvhTriangleMeshShape>(raw, true);
    }
  }
  return store.make<btEmptyShape>();
}

Real innerRadius(const ShapeDesc& s) {
  switch (s.type) {
    case ShapeType::Sphere:
    case ShapeType::Capsule: return s.radius;
    case ShapeType::Box: return s.half_extents.minCoeff();
    case ShapeType::Cylinder: return std::min(s.radius, s.half_height);
    case ShapeType::ConvexHull: {
      if (!s.hull || s.hull->vertices.empty()) return 0;
      Vec3 c = Vec3::Zero();
      for (const Vec3& v : s.hull->vertices) c += v;
      c /= static_cast<Real>(s.hull->vertices.size());
      Real r = kInf;
      for (size_t f = 0; f < s.hull->face_normals.size(); ++f)
        r = std::min(r, s.hull->face_offsets[f] - s.hull->face_normals[f].dot(c));
      return std::isfinite(r) ? std::max(r, Real(0)) : 0;
    }
    case ShapeType::Plane:
    case ShapeType::Mesh: return 0;
  }
  return 0;
}

}  // namespace cairn::validation::detail
