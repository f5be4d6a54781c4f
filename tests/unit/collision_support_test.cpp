// Support mappings and world bounds of every shape type.
#include "collision/aabb.hpp"
#include "collision/hull.hpp"
#include "collision/support.hpp"

#include <gtest/gtest.h>

#include <random>

namespace cairn {
namespace {

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<Real> g(0, 1);
  Vec3 v(g(rng), g(rng), g(rng));
  return v.normalized();
}

Transform randomTransform(std::mt19937& rng) {
  std::uniform_real_distribution<Real> u(-3, 3);
  Transform t;
  t.p = Vec3(u(rng), u(rng), u(rng));
  t.q = Quat(Eigen::AngleAxis<Real>(u(rng), randomUnit(rng)));
  return t;
}

// Points on the surface of each convex shape, in its own frame.
std::vector<Vec3> surfaceSamples(const ShapeDesc& s, std::mt19937& rng) {
  std::vector<Vec3> pts;
  std::uniform_real_distribution<Real> u(-1, 1);
  for (int i = 0; i < 4000; ++i) {
    const Vec3 dir = randomUnit(rng);
    switch (s.type) {
      case ShapeType::Sphere: pts.push_back(s.radius * dir); break;
      case ShapeType::Capsule: pts.push_back(Vec3(0, u(rng) * s.half_height, 0) + s.radius * dir); break;
      case ShapeType::Box: {
        Vec3 p(u(rng), u(rng), u(rng));
        p[i % 3] = dir[i % 3] < 0 ? -1 : 1;
        pts.push_back(p.cwiseProduct(s.half_extents));
        break;
      }
      case ShapeType::Cylinder: {
        const Real a = kPi * u(rng);
        pts.emplace_back(s.radius * std::cos(a), u(rng) * s.half_height, s.radius * std::sin(a));
        break;
      }
      default: break;
    }
  }
  if (s.type == ShapeType::ConvexHull) pts = s.hull->vertices;
  return pts;
}

std::vector<ShapeDesc> convexShapes() {
  std::vector<Vec3> cloud;
  std::mt19937 rng(3);
  for (int i = 0; i < 30; ++i) cloud.push_back(randomUnit(rng).cwiseProduct(Vec3(1, 0.6, 0.8)));
  ShapeDesc hull;
  hull.type = ShapeType::ConvexHull;
  hull.hull = buildConvexHull(cloud);
  return {ShapeDesc::sphere(0.7), ShapeDesc::box(Vec3(0.5, 1, 0.25)), ShapeDesc::capsule(0.3, 0.8),
          ShapeDesc::cylinder(0.6, 0.4), hull};
}

// The support point is the maximizer of d.x: no surface sample may beat it,
// and it must itself be a point of the shape (its value is attained by a
// sample to within the sampling density for smooth shapes). 1e-12: the
// comparison is a dot product of O(1) numbers.
TEST(CollisionSupport, SupportPointMaximizesDotOverSurfaceSamples) {
  std::mt19937 rng(5);
  for (const ShapeDesc& s : convexShapes()) {
    const std::vector<Vec3> pts = surfaceSamples(s, rng);
    for (int k = 0; k < 200; ++k) {
      const Vec3 d = randomUnit(rng) * 2.5;  // the length must not matter
      const Vec3 sp = supportLocal(s, d);
      Real best = -kInf;
      for (const Vec3& p : pts) best = std::max(best, d.dot(p));
      EXPECT_GE(d.dot(sp), best - 1e-12) << shapeTypeName(s.type);
      // The support value is attained: samples come within their spacing.
      EXPECT_LE(d.dot(sp), best + 0.1 * d.norm()) << shapeTypeName(s.type);
    }
  }
}

// The exact AABB of a convex set has faces e_i . s(+-e_i); every closed form
// in aabb.hpp must reproduce that.
TEST(CollisionSupport, WorldAabbIsTheBoxOfAxisSupports) {
  std::mt19937 rng(9);
  for (const ShapeDesc& s : convexShapes()) {
    for (int k = 0; k < 50; ++k) {
      const Transform t = randomTransform(rng);
      const Aabb box = shapeAabb(s, t);
      for (int i = 0; i < 3; ++i) {
        const Vec3 e = Vec3::Unit(i);
        EXPECT_NEAR(box.hi[i], supportWorld(s, t, e)[i], 1e-12) << shapeTypeName(s.type);
        EXPECT_NEAR(box.lo[i], supportWorld(s, t, -e)[i], 1e-12) << shapeTypeName(s.type);
      }
    }
  }
}

// A shape's box on a body is the box at the composed transform, to the
// bit, whatever shortcut a shape type takes (a sphere's skips the
// rotations): the broadphase's boxes, and so its pairs, do not move.
TEST(CollisionSupport, BodyShapeAabbIsTheBoxAtTheComposedTransformExactly) {
  std::mt19937 rng(11);
  for (ShapeDesc s : convexShapes()) {
    for (int k = 0; k < 50; ++k) {
      s.local = randomTransform(rng);
      const Transform body = randomTransform(rng);
      const Aabb composed = shapeAabb(s, body * s.local), placed = bodyShapeAabb(s, body);
      EXPECT_EQ(placed.lo, composed.lo) << shapeTypeName(s.type);
      EXPECT_EQ(placed.hi, composed.hi) << shapeTypeName(s.type);
    }
  }
}

TEST(CollisionSupport, PlaneAabbIsInfiniteAndAxisAlignedPlaneBoundsItsAxis) {
  Transform t;
  t.p = Vec3(0, 2, 0);
  const Aabb floor = shapeAabb(ShapeDesc::plane(Vec3(0, 1, 0), 0.5), t);
  EXPECT_TRUE(floor.isInfinite());
  EXPECT_EQ(floor.hi.y(), 2.5);
  EXPECT_EQ(floor.lo.y(), -kInf);
  EXPECT_EQ(floor.hi.x(), kInf);
  const Aabb tilted = shapeAabb(ShapeDesc::plane(Vec3(1, 1, 0), 0), Transform{});
  EXPECT_TRUE(tilted.isInfinite());
  EXPECT_TRUE(tilted.overlaps(Aabb::fromCenterHalf(Vec3(100, -50, 3), Vec3::Constant(1))));
}

TEST(CollisionSupport, MeshAndTriangleBounds) {
  auto mesh = std::make_shared<TriangleMeshData>();
  mesh->vertices = {{0, 0, 0}, {2, 0, 0}, {0, 1, -3}};
  mesh->triangles = {{0, 1, 2}};
  ShapeDesc s;
  s.type = ShapeType::Mesh;
  s.mesh = mesh;
  Transform t;
  t.p = Vec3(1, 1, 1);
  const Aabb box = shapeAabb(s, t);
  EXPECT_EQ(box.lo, Vec3(1, 1, -2));
  EXPECT_EQ(box.hi, Vec3(3, 2, 1));
  const Aabb tri = triangleAabb(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, -3));
  EXPECT_EQ(tri.lo, Vec3(0, 0, -3));
  EXPECT_EQ(tri.hi, Vec3(2, 1, 0));
  EXPECT_FALSE(tri.isInfinite());
}

}  // namespace
}  // namespace cairn
