// Contact manifolds for known configurations, with exact expected values.
//
// Tolerances: the dedicated routines (sphere, capsule, box, plane) are
// closed forms, so their results match to round-off (1e-12 on O(1)
// coordinates). Pairs through GJK / EPA (hulls, cylinders) converge exactly
// on flat faces; 1e-9 covers their round-off.
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using test::pose;
using test::rotation;

std::vector<Manifold> run(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin = 0.02) {
  std::vector<Manifold> out;
  const int n = collide(a, ta, b, tb, margin, out);
  EXPECT_EQ(n, static_cast<int>(out.size()));
  for (const Manifold& m : out) {
    EXPECT_NEAR(m.normal.norm(), 1, 1e-12);
    EXPECT_GE(m.count, 1);
    EXPECT_LE(m.count, 4);
  }
  return out;
}

// Points of m sorted by x then z, for comparing against a known list.
std::vector<ContactPoint> sorted(const Manifold& m) {
  std::vector<ContactPoint> p(m.points, m.points + m.count);
  std::sort(p.begin(), p.end(), [](const ContactPoint& a, const ContactPoint& b) {
    return a.position.x() != b.position.x() ? a.position.x() < b.position.x() : a.position.z() < b.position.z();
  });
  return p;
}

void expectVec(const Vec3& got, const Vec3& want, Real tol) { EXPECT_LT((got - want).norm(), tol) << got.transpose() << " vs " << want.transpose(); }

TEST(Manifold, BoxRestingFaceDownOnBoxHasFourPointsNormalUpExactDepth) {
  const ShapeDesc floor = ShapeDesc::box(Vec3(1, 0.5, 1));
  const ShapeDesc crate = ShapeDesc::box(Vec3(0.5, 0.5, 0.5));
  const Transform tf = pose(Vec3::Zero());
  const Transform tc = pose(Vec3(0, 0.99, 0));  // 0.01 into the floor
  auto out = run(floor, tf, crate, tc);
  ASSERT_EQ(out.size(), 1u);
  const Manifold& m = out[0];
  expectVec(m.normal, Vec3::UnitY(), 1e-12);
  ASSERT_EQ(m.count, 4);
  const auto p = sorted(m);
  const Vec3 want[4] = {{-0.5, 0.495, -0.5}, {-0.5, 0.495, 0.5}, {0.5, 0.495, -0.5}, {0.5, 0.495, 0.5}};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(p[i].depth, 0.01, 1e-12);
    expectVec(p[i].position, want[i], 1e-12);
  }
  // The other order flips the normal and nothing else.
  auto swapped = run(crate, tc, floor, tf);
  ASSERT_EQ(swapped.size(), 1u);
  expectVec(swapped[0].normal, -Vec3::UnitY(), 1e-12);
  ASSERT_EQ(swapped[0].count, 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(swapped[0].points[i].depth, 0.01, 1e-12);
  // Feature ids are distinct within the manifold.
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) EXPECT_NE(m.points[i].feature_id, m.points[j].feature_id);
}

TEST(Manifold, BoxSpeculativeContactAboveFaceHasNegativeDepth) {
  const ShapeDesc floor = ShapeDesc::box(Vec3(1, 0.5, 1));
  const ShapeDesc crate = ShapeDesc::box(Vec3(0.5, 0.5, 0.5));
  auto out = run(floor, pose(Vec3::Zero()), crate, pose(Vec3(0.2, 1.015, 0)), 0.02);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].count, 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(out[0].points[i].depth, -0.015, 1e-12);
  // Beyond the margin: nothing.
  EXPECT_TRUE(run(floor, pose(Vec3::Zero()), crate, pose(Vec3(0, 1.03, 0)), 0.02).empty());
}

TEST(Manifold, CrossedBoxEdgesMeetAtOnePoint) {
  // A's top edge runs along z at height sqrt(2)/2; B, turned about x, has
  // its bottom edge along x at height y_b - sqrt(2)/2. They cross at the
  // origin's vertical with 0.02 of overlap.
  const ShapeDesc cube = ShapeDesc::box(Vec3::Constant(0.5));
  const Real s = std::sqrt(Real(2)) / 2;
  const Transform ta = pose(Vec3::Zero(), rotation(kPi / 4, Vec3::UnitZ()));
  const Transform tb = pose(Vec3(0, 2 * s - 0.02, 0), rotation(kPi / 4, Vec3::UnitX()));
  auto out = run(cube, ta, cube, tb);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].count, 1);
  expectVec(out[0].normal, Vec3::UnitY(), 1e-12);
  EXPECT_NEAR(out[0].points[0].depth, 0.02, 1e-12);
  expectVec(out[0].points[0].position, Vec3(0, s - 0.01, 0), 1e-12);
}

TEST(Manifold, BoxBalancedOnCornerTouchesAtOnePoint) {
  // Turn the cube so its (1,1,1) corner points straight down.
  const Quat q = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), -Vec3::UnitY());
  const Real corner = std::sqrt(Real(3)) / 2;
  const ShapeDesc floor = ShapeDesc::box(Vec3(2, 0.5, 2));
  const ShapeDesc cube = ShapeDesc::box(Vec3::Constant(0.5));
  auto out = run(floor, pose(Vec3::Zero()), cube, pose(Vec3(0.3, 0.5 + corner - 0.01, -0.2), q));
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].count, 1);
  expectVec(out[0].normal, Vec3::UnitY(), 1e-12);
  EXPECT_NEAR(out[0].points[0].depth, 0.01, 1e-12);
  expectVec(out[0].points[0].position, Vec3(0.3, 0.495, -0.2), 1e-12);
}

TEST(Manifold, SphereSphere) {
  auto out = run(ShapeDesc::sphere(1), pose(Vec3(1, 2, 3)), ShapeDesc::sphere(0.5), pose(Vec3(2.2, 2, 3)));
  ASSERT_EQ(out.size(), 1u);
  expectVec(out[0].normal, Vec3::UnitX(), 1e-12);
  EXPECT_NEAR(out[0].points[0].depth, 0.3, 1e-12);
  // Surfaces at x = 2 (A) and x = 1.7 (B): midway 1.85.
  expectVec(out[0].points[0].position, Vec3(1.85, 2, 3), 1e-12);
}

TEST(Manifold, SphereBoxFaceEdgeCorner) {
  const ShapeDesc ball = ShapeDesc::sphere(0.5);
  const ShapeDesc box = ShapeDesc::box(Vec3(1, 1, 1));
  const Transform tb = pose(Vec3::Zero());
  // Face: center 0.4 above the top face.
  auto face = run(ball, pose(Vec3(0.3, 1.4, 0.2)), box, tb);
  ASSERT_EQ(face.size(), 1u);
  expectVec(face[0].normal, -Vec3::UnitY(), 1e-12);
  EXPECT_NEAR(face[0].points[0].depth, 0.1, 1e-12);
  expectVec(face[0].points[0].position, Vec3(0.3, 0.95, 0.2), 1e-12);
  // Edge: nearest box point (1, 1, 0.4) at distance 0.2 sqrt 2.
  const Real e = 0.2 * std::sqrt(Real(2));
  auto edge = run(ball, pose(Vec3(1.2, 1.2, 0.4)), box, tb);
  ASSERT_EQ(edge.size(), 1u);
  expectVec(edge[0].normal, Vec3(-1, -1, 0).normalized(), 1e-12);
  EXPECT_NEAR(edge[0].points[0].depth, 0.5 - e, 1e-12);
  // Corner: nearest point (1, 1, 1) at distance 0.2 sqrt 3.
  const Real c = 0.2 * std::sqrt(Real(3));
  auto corner = run(ball, pose(Vec3(1.2, 1.2, 1.2)), box, tb);
  ASSERT_EQ(corner.size(), 1u);
  expectVec(corner[0].normal, Vec3(-1, -1, -1).normalized(), 1e-12);
  EXPECT_NEAR(corner[0].points[0].depth, 0.5 - c, 1e-12);
  // Three distinct feature ids (face, edge and corner regions).
  EXPECT_NE(face[0].points[0].feature_id, edge[0].points[0].feature_id);
  EXPECT_NE(edge[0].points[0].feature_id, corner[0].points[0].feature_id);
  // Center inside the box: pushed out through the nearest face (+x here).
  auto inside = run(ball, pose(Vec3(0.8, 0.1, 0)), box, tb);
  ASSERT_EQ(inside.size(), 1u);
  expectVec(inside[0].normal, -Vec3::UnitX(), 1e-12);
  EXPECT_NEAR(inside[0].points[0].depth, 0.5 + 0.2, 1e-12);
}

TEST(Manifold, CapsuleLyingOnBoxHasTwoPoints) {
  const ShapeDesc box = ShapeDesc::box(Vec3(2, 0.5, 2));
  const ShapeDesc cap = ShapeDesc::capsule(0.25, 1);
  const Transform tc = pose(Vec3(0.1, 0.5 + 0.25 - 0.01, 0.3), rotation(kPi / 2, Vec3::UnitZ()));  // axis along x
  auto out = run(box, pose(Vec3::Zero()), cap, tc);
  ASSERT_EQ(out.size(), 1u);
  expectVec(out[0].normal, Vec3::UnitY(), 1e-12);
  ASSERT_EQ(out[0].count, 2);
  const auto p = sorted(out[0]);
  expectVec(p[0].position, Vec3(-0.9, 0.495, 0.3), 1e-12);
  expectVec(p[1].position, Vec3(1.1, 0.495, 0.3), 1e-12);
  EXPECT_NEAR(p[0].depth, 0.01, 1e-12);
  EXPECT_NEAR(p[1].depth, 0.01, 1e-12);
}

TEST(Manifold, CapsuleOverhangingBoxEdgeIsClippedToTheFace) {
  const ShapeDesc box = ShapeDesc::box(Vec3(1, 0.5, 1));
  const ShapeDesc cap = ShapeDesc::capsule(0.25, 1);
  auto out = run(box, pose(Vec3::Zero()), cap, pose(Vec3(0.5, 0.74, 0), rotation(kPi / 2, Vec3::UnitZ())));
  ASSERT_EQ(out.size(), 1u);
  ASSERT_EQ(out[0].count, 2);
  const auto p = sorted(out[0]);
  EXPECT_NEAR(p[0].position.x(), -0.5, 1e-12);
  EXPECT_NEAR(p[1].position.x(), 1.0, 1e-12);  // clipped at the box's rim
}

TEST(Manifold, CapsuleCapsuleParallelTwoPointsCrossedOne) {
  const ShapeDesc cap = ShapeDesc::capsule(0.25, 1);
  const Quat along_x = rotation(kPi / 2, Vec3::UnitZ());
  // Parallel, overlapping over x in [-0.5, 1]; 0.05 deep.
  auto par = run(cap, pose(Vec3::Zero(), along_x), cap, pose(Vec3(0.5, 0.45, 0), along_x));
  ASSERT_EQ(par.size(), 1u);
  expectVec(par[0].normal, Vec3::UnitY(), 1e-12);
  ASSERT_EQ(par[0].count, 2);
  const auto p = sorted(par[0]);
  expectVec(p[0].position, Vec3(-0.5, 0.225, 0), 1e-12);
  expectVec(p[1].position, Vec3(1, 0.225, 0), 1e-12);
  EXPECT_NEAR(p[0].depth, 0.05, 1e-12);
  EXPECT_NEAR(p[1].depth, 0.05, 1e-12);
  // Crossed: one point where the axes pass.
  auto crossed = run(cap, pose(Vec3::Zero(), along_x), cap, pose(Vec3(0.2, 0.45, 0.3), rotation(kPi / 2, Vec3::UnitX())));
  ASSERT_EQ(crossed.size(), 1u);
  ASSERT_EQ(crossed[0].count, 1);
  expectVec(crossed[0].normal, Vec3::UnitY(), 1e-12);
  EXPECT_NEAR(crossed[0].points[0].depth, 0.05, 1e-12);
  expectVec(crossed[0].points[0].position, Vec3(0.2, 0.225, 0), 1e-12);
}

TEST(Manifold, CylinderStandingOnPlaneTouchesAtRimPoints) {
  const ShapeDesc ground = ShapeDesc::plane(Vec3::UnitY(), 0);
  const ShapeDesc cyl = ShapeDesc::cylinder(0.5, 1);
  auto out = run(ground, pose(Vec3::Zero()), cyl, pose(Vec3(2, 0.99, 1)));
  ASSERT_EQ(out.size(), 1u);
  expectVec(out[0].normal, Vec3::UnitY(), 1e-12);
  ASSERT_EQ(out[0].count, 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(out[0].points[i].depth, 0.01, 1e-12);
    EXPECT_NEAR(out[0].points[i].position.y(), -0.005, 1e-12);
    EXPECT_NEAR((out[0].points[i].position - Vec3(2, -0.005, 1)).norm(), 0.5, 1e-12);  // on the rim
  }
  // Tilted onto its rim: the deepest point is the lowest rim point.
  const Real tilt = 0.3;
  const Transform tt = pose(Vec3(0, 1 * std::cos(tilt) + 0.5 * std::sin(tilt) - 0.01, 0), rotation(tilt, Vec3::UnitZ()));
  auto rim = run(ground, pose(Vec3::Zero()), cyl, tt);
  ASSERT_EQ(rim.size(), 1u);
  EXPECT_NEAR(test::maxDepth(rim[0]), 0.01, 1e-12);
  // Lying on its side: a line contact, two points (one per cap).
  auto side = run(ground, pose(Vec3::Zero()), cyl, pose(Vec3(0, 0.49, 0), rotation(kPi / 2, Vec3::UnitX())));
  ASSERT_EQ(side.size(), 1u);
  ASSERT_EQ(side[0].count, 2);
  EXPECT_NEAR(side[0].points[0].depth, 0.01, 1e-12);
  EXPECT_NEAR(side[0].points[1].depth, 0.01, 1e-12);
}

TEST(Manifold, SphereAndCapsuleAndBoxOnPlane) {
  const ShapeDesc ground = ShapeDesc::plane(Vec3(0, 2, 0), 1);  // y <= 0.5, normal not unit
  auto s = run(ground, pose(Vec3::Zero()), ShapeDesc::sphere(0.5), pose(Vec3(0, 0.9, 0)));
  ASSERT_EQ(s.size(), 1u);
  EXPECT_NEAR(s[0].points[0].depth, 0.1, 1e-12);
  auto c = run(ground, pose(Vec3::Zero()), ShapeDesc::capsule(0.25, 1), pose(Vec3(0, 0.7, 0), rotation(kPi / 2, Vec3::UnitX())));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].count, 2);
  auto b = run(ShapeDesc::box(Vec3::Constant(0.5)), pose(Vec3(0, 0.95, 0)), ground, pose(Vec3::Zero()));
  ASSERT_EQ(b.size(), 1u);
  expectVec(b[0].normal, -Vec3::UnitY(), 1e-12);  // box first: normal toward the plane
  EXPECT_EQ(b[0].count, 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(b[0].points[i].depth, 0.05, 1e-12);
}

TEST(Manifold, HullOnPlaneFaceDownAndOnAVertex) {
  const ShapeDesc ground = ShapeDesc::plane(Vec3::UnitY(), 0);
  const ShapeDesc cube = test::cubeHull(0.5);
  auto face = run(ground, pose(Vec3::Zero()), cube, pose(Vec3(0, 0.49, 0)));
  ASSERT_EQ(face.size(), 1u);
  EXPECT_EQ(face[0].count, 4);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(face[0].points[i].depth, 0.01, 1e-12);
  const Quat q = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), -Vec3::UnitY());
  auto vertex = run(ground, pose(Vec3::Zero()), cube, pose(Vec3(0, std::sqrt(Real(3)) / 2 - 0.01, 0), q));
  ASSERT_EQ(vertex.size(), 1u);
  ASSERT_EQ(vertex[0].count, 1);
  EXPECT_NEAR(vertex[0].points[0].depth, 0.01, 1e-12);
  expectVec(vertex[0].points[0].position, Vec3(0, -0.005, 0), 1e-12);
}

TEST(Manifold, BoxRestingOnHullGetsFourPointsThroughGjkAndClipping) {
  const ShapeDesc slab = test::hullShape({{-2, -0.5, -2}, {2, -0.5, -2}, {2, -0.5, 2}, {-2, -0.5, 2}, {-2, 0.5, -2}, {2, 0.5, -2}, {2, 0.5, 2}, {-2, 0.5, 2}});
  const ShapeDesc crate = ShapeDesc::box(Vec3::Constant(0.5));
  for (const Real gap : {-0.01, 0.005}) {  // penetrating (EPA) and speculative (GJK)
    auto out = run(slab, pose(Vec3::Zero()), crate, pose(Vec3(0.3, 1 + gap, 0), rotation(0.4, Vec3::UnitY())));
    ASSERT_EQ(out.size(), 1u) << gap;
    expectVec(out[0].normal, Vec3::UnitY(), 1e-9);
    ASSERT_EQ(out[0].count, 4) << gap;
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(out[0].points[i].depth, -gap, 1e-9);
  }
  // And a hull resting on a hull.
  auto hh = run(slab, pose(Vec3::Zero()), test::cubeHull(0.5), pose(Vec3(0, 0.99, 0)));
  ASSERT_EQ(hh.size(), 1u);
  EXPECT_EQ(hh[0].count, 4);
  EXPECT_NEAR(test::maxDepth(hh[0]), 0.01, 1e-9);
}

TEST(Manifold, CylinderStandingOnBoxGetsMultiplePoints) {
  const ShapeDesc box = ShapeDesc::box(Vec3(2, 0.5, 2));
  auto out = run(box, pose(Vec3::Zero()), ShapeDesc::cylinder(0.5, 1), pose(Vec3(0.2, 1.49, 0)));
  ASSERT_EQ(out.size(), 1u);
  expectVec(out[0].normal, Vec3::UnitY(), 1e-9);
  EXPECT_EQ(out[0].count, 4);
  for (int i = 0; i < out[0].count; ++i) EXPECT_NEAR(out[0].points[i].depth, 0.01, 1e-9);
}

TEST(Manifold, MeshGivesOneManifoldPerTouchingTriangle) {
  // Two triangles forming the square [-2, 2]^2 at y = 0, counter-clockwise
  // seen from above.
  auto mesh = std::make_shared<TriangleMeshData>();
  mesh->vertices = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  mesh->triangles = {{0, 2, 1}, {0, 3, 2}};
  ShapeDesc ground;
  ground.type = ShapeType::Mesh;
  ground.mesh = mesh;
  // A sphere over the middle of the first triangle.
  auto s = run(ground, pose(Vec3::Zero()), ShapeDesc::sphere(0.5), pose(Vec3(1, 0.45, -1)));
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].triangle, 0);
  expectVec(s[0].normal, Vec3::UnitY(), 1e-9);
  EXPECT_NEAR(s[0].points[0].depth, 0.05, 1e-9);
  // A box straddling the diagonal touches both triangles.
  auto b = run(ground, pose(Vec3::Zero()), ShapeDesc::box(Vec3::Constant(0.5)), pose(Vec3(0, 0.49, 0)));
  ASSERT_EQ(b.size(), 2u);
  for (const Manifold& m : b) {
    expectVec(m.normal, Vec3::UnitY(), 1e-9);
    EXPECT_NEAR(test::maxDepth(m), 0.01, 1e-9);
  }
  EXPECT_NE(b[0].triangle, b[1].triangle);
  // Mesh second: normals flip.
  auto flipped = run(ShapeDesc::sphere(0.5), pose(Vec3(1, 0.45, -1)), ground, pose(Vec3::Zero()));
  ASSERT_EQ(flipped.size(), 1u);
  expectVec(flipped[0].normal, -Vec3::UnitY(), 1e-9);
}

TEST(Manifold, FeatureIdsAreStableWhileTheSameFeaturesTouch) {
  const ShapeDesc floor = ShapeDesc::box(Vec3(2, 0.5, 2));
  const ShapeDesc crate = ShapeDesc::box(Vec3::Constant(0.5));
  auto first = run(floor, pose(Vec3::Zero()), crate, pose(Vec3(0, 0.99, 0), rotation(0.1, Vec3::UnitY())));
  // Slide a little, turn a little, sink a little: same faces in touch.
  auto later = run(floor, pose(Vec3::Zero()), crate, pose(Vec3(0.05, 0.985, 0.02), rotation(0.12, Vec3::UnitY())));
  ASSERT_EQ(first.size(), 1u);
  ASSERT_EQ(later.size(), 1u);
  ASSERT_EQ(first[0].count, 4);
  ASSERT_EQ(later[0].count, 4);
  // Each id of the first frame appears in the later frame, at the point that
  // moved least.
  for (int i = 0; i < 4; ++i) {
    int match = -1;
    for (int j = 0; j < 4; ++j)
      if (later[0].points[j].feature_id == first[0].points[i].feature_id) match = j;
    ASSERT_GE(match, 0) << "id " << std::hex << first[0].points[i].feature_id;
    EXPECT_LT((later[0].points[match].position - first[0].points[i].position).norm(), 0.2);
  }
}

// Coincident identical bodies: the contact normal is arbitrary but must be
// finite and unit, and the depth finite and positive.
TEST(Manifold, IdenticalCoincidentBodiesGiveFiniteOutput) {
  const std::vector<ShapeDesc> shapes = {ShapeDesc::sphere(0.5), ShapeDesc::box(Vec3(0.5, 0.3, 0.4)),
                                         ShapeDesc::capsule(0.3, 0.5), ShapeDesc::cylinder(0.4, 0.5), test::cubeHull(0.5),
                                         test::blobHull()};
  const Transform t = pose(Vec3(1, 2, 3), rotation(0.7, Vec3(1, 2, 3)));
  for (const ShapeDesc& s : shapes) {
    for (const ShapeDesc& o : shapes) {
      std::vector<Manifold> out;
      ASSERT_EQ(collide(s, t, o, t, 0.01, out), 1) << shapeTypeName(s.type) << "-" << shapeTypeName(o.type);
      const Manifold& m = out[0];
      EXPECT_TRUE(m.normal.allFinite());
      EXPECT_NEAR(m.normal.norm(), 1, 1e-9);
      ASSERT_GE(m.count, 1);
      for (int i = 0; i < m.count; ++i) {
        EXPECT_TRUE(m.points[i].position.allFinite());
        EXPECT_TRUE(std::isfinite(m.points[i].depth));
      }
      EXPECT_GT(test::maxDepth(m), 0) << shapeTypeName(s.type) << "-" << shapeTypeName(o.type);
    }
  }
}

TEST(Manifold, StaticPairsProduceNothing) {
  std::vector<Manifold> out;
  const ShapeDesc plane = ShapeDesc::plane(Vec3::UnitY(), 0);
  EXPECT_EQ(collide(plane, pose(Vec3::Zero()), plane, pose(Vec3::Zero()), 0.1, out), 0);
  EXPECT_FALSE(canCollide(ShapeType::Plane, ShapeType::Mesh));
  EXPECT_TRUE(canCollide(ShapeType::Box, ShapeType::Mesh));
}

}  // namespace
}  // namespace cairn
