// Shape casts (sphere, box, capsule swept along a translation) against every
// shape type, checked against closed forms.
//
// A sphere of radius r swept against a shape S touches it when its center
// enters S grown by r (the Minkowski sum), so a sphere cast equals a ray
// cast from the center against the inflated shape: a sphere of radius
// r + r_S, a capsule of radius r + r_S, or a box with rounded edges and
// corners (three stretched boxes, twelve edge capsules and eight corner
// spheres; the first entry into a union is the first entry into any part).
// Those ray casts are the closed forms of ray_cast.cpp, a separate code path
// from the GJK ray cast under test.
//
// Tolerances: the GJK ray cast stops within 1e-10 of the shapes' size of
// touching, and never past it; with translations of length 2-6 that meet
// the surface at a reasonable angle (rays aimed at interior points) the
// fraction is within 1e-9 of exact. Rounded shapes report the normal
// v / |v| with |v| = the sum of radii, accurate to 1e-10 / radius.
#include "collision/mesh_bvh.hpp"
#include "collision/ray_cast.hpp"
#include "collision/shape_cast.hpp"
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using test::pose;
using test::rotation;

constexpr Real kFraction = 1e-9;
constexpr Real kNormal = 1e-8;

void expectVecNear(const Vec3& a, const Vec3& b, Real tol) {
  EXPECT_LE((a - b).norm(), tol) << "got " << a.transpose() << ", want " << b.transpose();
}

// First entry of the segment into a box of half extents h grown by a ball of
// radius r, at pose t, as the first entry into any of its parts.
std::optional<CastHit> rayRoundedBox(const Vec3& h, Real r, const Transform& t, const Vec3& o, const Vec3& d) {
  std::optional<CastHit> best;
  auto keep = [&](const ShapeDesc& s, const Transform& local) {
    const auto hit = rayCast(s, t * local, o, d);
    if (hit && (!best || hit->fraction < best->fraction)) best = hit;
  };
  for (int i = 0; i < 3; ++i) {
    Vec3 stretched = h;
    stretched[i] += r;
    keep(ShapeDesc::box(stretched), pose(Vec3::Zero()));
    // Edges along axis i at (+-h_j, +-h_k): capsules whose local y is e_i.
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const Quat along = Quat::FromTwoVectors(Vec3::UnitY(), Vec3::Unit(i));
    for (const Real sj : {-1.0, 1.0})
      for (const Real sk : {-1.0, 1.0}) {
        Vec3 c = Vec3::Zero();
        c[j] = sj * h[j];
        c[k] = sk * h[k];
        keep(ShapeDesc::capsule(r, h[i]), pose(c, along));
      }
  }
  return best;  // the corner spheres are the capsules' end caps
}

// A random unit quaternion (uniform enough for test poses).
Quat randomRotation(std::mt19937& rng) {
  std::normal_distribution<Real> g(0, 1);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

// Sweeps a sphere of radius r from random points toward random points
// near `target_pose`, and compares with the ray cast `inflated` gives.
template <class Inflated>
void expectSphereCastMatchesInflatedRay(const ShapeDesc& target, const Transform& target_pose, Real r, Real aim,
                                        Inflated&& inflated, unsigned seed) {
  const ShapeDesc sphere = ShapeDesc::sphere(r);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 200; ++i) {
    const Vec3 from = target_pose.p + 3 * Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 to = target_pose.p + aim * Vec3(u(rng), u(rng), u(rng));
    const Vec3 d = 1.5 * (to - from);
    const std::optional<CastHit> want = inflated(from, d);
    const std::optional<CastHit> got = shapeCast(sphere, pose(from, randomRotation(rng)), d, target, target_pose);
    ASSERT_EQ(got.has_value(), want.has_value()) << i;
    if (!got) continue;
    ASSERT_FALSE(want->inside) << "the test starts every sphere outside";
    ++hits;
    EXPECT_FALSE(got->inside);
    EXPECT_NEAR(got->fraction, want->fraction, kFraction) << i;
    expectVecNear(got->normal, want->normal, kNormal);
    // The contact point is the center at impact moved back by r.
    expectVecNear(got->point, want->point - r * want->normal, 1e-8);
  }
  EXPECT_GT(hits, 150);
}

TEST(ShapeCastSphere, EqualsARayCastAgainstTheInflatedSphere) {
  const Transform tp = pose(Vec3(0.4, 1, -0.3));
  expectSphereCastMatchesInflatedRay(ShapeDesc::sphere(0.6), tp, 0.35, 0.5,
                                     [&](const Vec3& o, const Vec3& d) { return rayCast(ShapeDesc::sphere(0.95), tp, o, d); }, 1);
}

TEST(ShapeCastSphere, EqualsARayCastAgainstTheRoundedBox) {
  const Vec3 h(0.5, 0.3, 0.8);
  const Transform tp = pose(Vec3(-0.2, 0.5, 1), rotation(0.6, Vec3(1, 1, 0)));
  expectSphereCastMatchesInflatedRay(ShapeDesc::box(h), tp, 0.25, 0.6,
                                     [&](const Vec3& o, const Vec3& d) { return rayRoundedBox(h, 0.25, tp, o, d); }, 2);
}

TEST(ShapeCastSphere, EqualsARayCastAgainstTheRoundedCubeHull) {
  const Transform tp = pose(Vec3(1, 0, 0), rotation(-0.4, Vec3(0, 1, 2)));
  expectSphereCastMatchesInflatedRay(test::cubeHull(0.5), tp, 0.3, 0.6,
                                     [&](const Vec3& o, const Vec3& d) { return rayRoundedBox(Vec3::Constant(0.5), 0.3, tp, o, d); },
                                     3);
}

TEST(ShapeCastSphere, EqualsARayCastAgainstTheInflatedCapsule) {
  const Transform tp = pose(Vec3(0, 0.2, 0.1), rotation(1.1, Vec3(0.3, 0, 1)));
  expectSphereCastMatchesInflatedRay(ShapeDesc::capsule(0.3, 0.7), tp, 0.2, 0.6,
                                     [&](const Vec3& o, const Vec3& d) { return rayCast(ShapeDesc::capsule(0.5, 0.7), tp, o, d); }, 4);
}

TEST(ShapeCastSphere, OntoACylinderCapAndSideAtTheClosedFormFraction) {
  // Curved core: GJK converges to the tolerance instead of terminating.
  const Real r = 0.25, R = 0.6, hh = 0.5;
  const Transform tc = pose(Vec3(1, 2, 3), rotation(0.8, Vec3(1, 0, 1)));
  const ShapeDesc sphere = ShapeDesc::sphere(r), cyl = ShapeDesc::cylinder(R, hh);
  const Vec3 from_cap = tc.apply(Vec3(0.2, 3, -0.1)), down = tc.q * Vec3(0, -4, 0);
  const auto cap = shapeCast(sphere, pose(from_cap), down, cyl, tc);
  ASSERT_TRUE(cap);
  EXPECT_NEAR(cap->fraction, (3 - hh - r) / 4, kFraction);
  expectVecNear(cap->normal, tc.q * Vec3::UnitY(), kNormal);
  expectVecNear(cap->point, tc.apply(Vec3(0.2, hh, -0.1)), 1e-8);
  const Vec3 dir = Vec3(1, 0, 2).normalized();
  const auto side = shapeCast(sphere, pose(tc.apply(Vec3(0, 0.1, 0) + 4 * dir)), tc.q * (-6 * dir), cyl, tc);
  ASSERT_TRUE(side);
  EXPECT_NEAR(side->fraction, (4 - R - r) / 6, kFraction);
  expectVecNear(side->normal, tc.q * dir, kNormal);
}

TEST(ShapeCastSphere, PassingBesideBy1e6MissesAndGrazingBy1e6Hits) {
  // Clearance 1e-6 is 10^4 times the cast tolerance.
  const ShapeDesc a = ShapeDesc::sphere(0.5), b = ShapeDesc::sphere(0.5);
  EXPECT_FALSE(shapeCast(a, pose(Vec3(-3, 1 + 1e-6, 0)), Vec3(6, 0, 0), b, pose(Vec3::Zero())));
  const auto hit = shapeCast(a, pose(Vec3(-3, 1 - 1e-6, 0)), Vec3(6, 0, 0), b, pose(Vec3::Zero()));
  ASSERT_TRUE(hit);
  const Real y = 1 - 1e-6;
  EXPECT_NEAR(hit->fraction, (3 - std::sqrt(1 - y * y)) / 6, kFraction);
  // Moving away never hits.
  EXPECT_FALSE(shapeCast(a, pose(Vec3(-3, 0, 0)), Vec3(-6, 0, 0), b, pose(Vec3::Zero())));
}

TEST(ShapeCastBox, OntoATiltedPlaneAtTheLowestCornersFraction) {
  // The lowest corner of a box (rotation R, half extents h, center c) above
  // the plane n.x <= e is at height n.c - sum_i h_i |n.R e_i| - e; the box
  // reaches the plane after that height over the approach speed -n.t.
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-1, 1);
  const Vec3 h(0.4, 0.2, 0.7);
  const ShapeDesc box = ShapeDesc::box(h);
  const Transform tp = pose(Vec3(0, -1, 0), rotation(0.3, Vec3(1, 0, 0.5)));
  const ShapeDesc plane = ShapeDesc::plane(Vec3(0, 3, 0), 1.5);  // y <= 0.5 in its frame
  Vec3 n;
  Real e;
  worldPlane(plane, tp, n, e);
  for (int i = 0; i < 50; ++i) {
    const Quat q = randomRotation(rng);
    const Mat3 rot = q.toRotationMatrix();
    const Vec3 c = tp.apply(Vec3(u(rng), 3 + u(rng), u(rng)));
    const Vec3 t = tp.q * Vec3(u(rng), -5, u(rng));
    Real height = n.dot(c) - e;
    Vec3 corner = c;
    for (int k = 0; k < 3; ++k) {
      const Real s = n.dot(rot.col(k)) > 0 ? -1 : 1;
      height -= h[k] * std::abs(n.dot(rot.col(k)));
      corner += s * h[k] * rot.col(k);
    }
    const auto hit = shapeCast(box, pose(c, q), t, plane, tp);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->fraction, height / -n.dot(t), 1e-12);
    expectVecNear(hit->normal, n, 1e-15);
    expectVecNear(hit->point, corner + hit->fraction * t, 1e-12);
  }
}

TEST(ShapeCastBox, CornerFirstOntoABoxAtTheLowestCornersFraction) {
  // No rounding: the GJK ray cast terminates on polytopes. The normal is
  // the ground's face normal (a corner meets a face).
  std::mt19937 rng(6);
  std::uniform_real_distribution<Real> u(-1, 1);
  const Vec3 h(0.5, 0.3, 0.4);
  const ShapeDesc box = ShapeDesc::box(h), ground = ShapeDesc::box(Vec3(5, 0.5, 5));
  const Transform tg = pose(Vec3(0, -0.5, 0));
  for (int i = 0; i < 50; ++i) {
    const Quat q = randomRotation(rng);
    const Mat3 rot = q.toRotationMatrix();
    const Vec3 c(u(rng), 2 + u(rng), u(rng));
    const Vec3 t(0.5 * u(rng), -3, 0.5 * u(rng));
    Real lowest = c.y();
    for (int k = 0; k < 3; ++k) lowest -= h[k] * std::abs(rot(1, k));
    const auto hit = shapeCast(box, pose(c, q), t, ground, tg);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->fraction, lowest / 3, kFraction);
    expectVecNear(hit->normal, Vec3::UnitY(), kNormal);
    EXPECT_NEAR(hit->point.y(), 0, 1e-8);
  }
}

TEST(ShapeCastBox, FaceOntoACylinderSideAtTheClosedFormFraction) {
  // Neither shape is rounded and the cylinder's side is curved: the normal
  // is the last supporting plane's, through a point within the tolerance
  // 1e-10 of the surface. That bounds its error by sqrt(2 * 1e-10 / R)
  // (2e-5) only; measured: 3e-10 for the normal and 7e-9 for the contact
  // line's position, checked here at 100 times that.
  const Real R = 0.5, hx = 0.3;
  const auto hit = shapeCast(ShapeDesc::box(Vec3(hx, 0.2, 0.2)), pose(Vec3(3, 0.1, 0.05)), Vec3(-4, 0, 0),
                             ShapeDesc::cylinder(R, 1), pose(Vec3::Zero()));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->fraction, (3 - R - hx) / 4, kFraction);
  expectVecNear(hit->normal, Vec3::UnitX(), 1e-7);
  // The box's face meets the side along a vertical line: any point of it
  // within the box's height is the contact.
  EXPECT_NEAR(hit->point.x(), R, 1e-9);
  EXPECT_NEAR(hit->point.z(), 0, 1e-6);
  EXPECT_LE(std::abs(hit->point.y() - 0.1), 0.2 + 1e-9);
}

TEST(ShapeCastCapsule, LyingCapsuleOntoABoxAndCrossedCapsulesAtTheClosedFormFraction) {
  const Real r = 0.2;
  const ShapeDesc cap = ShapeDesc::capsule(r, 0.6);
  const Quat lying = rotation(kPi / 2, Vec3::UnitZ());  // axis along x
  const auto onto_box = shapeCast(cap, pose(Vec3(0.1, 2, 0.3), lying), Vec3(0.2, -4, 0), ShapeDesc::box(Vec3(2, 0.5, 2)),
                                  pose(Vec3(0, 0, 0)));
  ASSERT_TRUE(onto_box);
  EXPECT_NEAR(onto_box->fraction, (2 - r - 0.5) / 4, kFraction);
  expectVecNear(onto_box->normal, Vec3::UnitY(), kNormal);
  EXPECT_NEAR(onto_box->point.y(), 0.5, 1e-9);
  // Crossed: A along x above B along z; they touch when the axes are
  // r_A + r_B apart, at B's top.
  const ShapeDesc other = ShapeDesc::capsule(0.3, 1);
  const Transform tb = pose(Vec3(0.5, -1, 0.2), rotation(kPi / 2, Vec3::UnitX()));  // axis along z
  const auto crossed = shapeCast(cap, pose(Vec3(0.5, 1, 0.2), lying), Vec3(0, -3, 0), other, tb);
  ASSERT_TRUE(crossed);
  EXPECT_NEAR(crossed->fraction, (2 - r - 0.3) / 3, kFraction);
  expectVecNear(crossed->normal, Vec3::UnitY(), kNormal);
  expectVecNear(crossed->point, Vec3(0.5, -0.7, 0.2), 1e-8);
  // Standing capsule onto a plane: its bottom at c_y - hh - r.
  const auto plane = shapeCast(cap, pose(Vec3(0, 3, 0)), Vec3(0, -4, 0), ShapeDesc::plane(Vec3::UnitY(), 0.5),
                               pose(Vec3::Zero()));
  ASSERT_TRUE(plane);
  EXPECT_NEAR(plane->fraction, (3 - 0.6 - r - 0.5) / 4, 1e-12);
}

TEST(ShapeCastAnyShape, OverlappingAtTheStartHitsAtZeroInside) {
  const Vec3 t(0, 0, 2);
  for (const ShapeDesc& moving : {ShapeDesc::sphere(0.3), ShapeDesc::box(Vec3(0.2, 0.3, 0.2)), ShapeDesc::capsule(0.2, 0.3)})
    for (const ShapeDesc& target : {ShapeDesc::box(Vec3::Ones()), ShapeDesc::sphere(1), ShapeDesc::plane(Vec3::UnitY(), 0.9)}) {
      const auto hit = shapeCast(moving, pose(Vec3(0.1, 0.8, 0)), t, target, pose(Vec3::Zero()));
      ASSERT_TRUE(hit);
      EXPECT_TRUE(hit->inside);
      EXPECT_EQ(hit->fraction, 0);
      expectVecNear(hit->normal, -Vec3::UnitZ(), 1e-15);
      expectVecNear(hit->point, Vec3(0.1, 0.8, 0), 0);
    }
}

TEST(ShapeCastAnyShape, TouchingAtTheStartHitsOnlyWhenPushingIn) {
  // A sphere, a box and a capsule resting exactly on a box (cores apart by
  // the radii, or faces coincident) and on a plane: down is a hit at 0
  // with the surface normal; up and sideways are misses.
  const ShapeDesc ground = ShapeDesc::box(Vec3(3, 0.5, 3)), plane = ShapeDesc::plane(Vec3::UnitY(), 0.5);
  const struct {
    ShapeDesc s;
    Real half_height;
  } movers[] = {{ShapeDesc::sphere(0.3), 0.3}, {ShapeDesc::box(Vec3(0.2, 0.25, 0.2)), 0.25}, {ShapeDesc::capsule(0.2, 0.3), 0.5}};
  for (const auto& m : movers)
    for (const ShapeDesc* target : {&ground, &plane}) {
      const Transform at = pose(Vec3(0.1, 0.5 + m.half_height, -0.2));
      const auto down = shapeCast(m.s, at, Vec3(0.3, -1, 0), *target, pose(Vec3::Zero()));
      ASSERT_TRUE(down) << shapeTypeName(m.s.type);
      EXPECT_FALSE(down->inside);
      EXPECT_EQ(down->fraction, 0);
      expectVecNear(down->normal, Vec3::UnitY(), kNormal);
      EXPECT_FALSE(shapeCast(m.s, at, Vec3(0.3, 1, 0), *target, pose(Vec3::Zero()))) << shapeTypeName(m.s.type);
      EXPECT_FALSE(shapeCast(m.s, at, Vec3(1, 0, 0.5), *target, pose(Vec3::Zero()))) << shapeTypeName(m.s.type);
    }
}

TEST(ShapeCastMesh, SphereOntoAFlatQuadAtTheClosedFormFraction) {
  const ShapeDesc mesh = test::quadMesh();
  const Transform tm = pose(Vec3(0, 1, 0), rotation(0.2, Vec3(1, 0, 0)));
  const auto hit = shapeCast(ShapeDesc::sphere(0.25), pose(tm.apply(Vec3(0.5, 2, -0.3))), tm.q * Vec3(0, -3, 0), mesh, tm);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->fraction, (2 - 0.2 - 0.25) / 3, kFraction);
  EXPECT_EQ(hit->triangle, 1);  // x > z
  expectVecNear(hit->normal, tm.q * Vec3::UnitY(), kNormal);
  expectVecNear(hit->point, tm.apply(Vec3(0.5, 0.2, -0.3)), 1e-8);
}

TEST(ShapeCastMesh, BvhWalkFindsTheSameFirstTriangleAsCastingAgainstEveryTriangle) {
  const ShapeDesc mesh = test::meshShape(test::bumpyTerrain(24, 3, 0.3, true));
  const TriangleMeshData& md = *mesh.mesh;
  const Transform tm = pose(Vec3(0.5, -0.2, 0), rotation(0.3, Vec3(0, 1, 0.2)));
  std::mt19937 rng(9);
  std::uniform_real_distribution<Real> u(-1, 1);
  const ShapeDesc movers[] = {ShapeDesc::sphere(0.2), ShapeDesc::box(Vec3(0.3, 0.1, 0.2)), ShapeDesc::capsule(0.15, 0.3)};
  int hits = 0;
  for (int i = 0; i < 60; ++i) {
    const ShapeDesc& s = movers[i % 3];
    const Transform at = pose(tm.apply(Vec3(2 * u(rng), 1.5 + 0.5 * u(rng), 2 * u(rng))), randomRotation(rng));
    const Vec3 t = tm.q * Vec3(u(rng), -3, u(rng));
    // Brute force: each triangle as its own one-triangle mesh.
    std::optional<CastHit> best;
    for (int k = 0; k < static_cast<int>(md.triangles.size()); ++k) {
      auto one = std::make_shared<TriangleMeshData>();
      one->vertices = md.vertices;
      one->triangles = {md.triangles[k]};
      auto h = shapeCast(s, at, t, test::meshShape(one), tm);
      if (h && (!best || h->fraction < best->fraction)) best = h, best->triangle = k;
    }
    const auto got = shapeCast(s, at, t, mesh, tm);
    ASSERT_EQ(got.has_value(), best.has_value()) << i;
    if (!got) continue;
    ++hits;
    EXPECT_EQ(got->triangle, best->triangle) << i;
    EXPECT_EQ(got->fraction, best->fraction) << i;
    expectVecNear(got->normal, best->normal, 0);
  }
  EXPECT_GT(hits, 50);
}

TEST(ShapeCastAnyShape, EndsShortOfContactAtMaxFractionAndIgnoresNonConvexMovers) {
  const ShapeDesc a = ShapeDesc::sphere(0.5), b = ShapeDesc::box(Vec3::Constant(0.5));
  // Contact after a translation of 2 of the 3 along x.
  EXPECT_FALSE(shapeCast(a, pose(Vec3(-3, 0, 0)), Vec3(3, 0, 0), b, pose(Vec3::Zero()), 2.0 / 3 - 1e-6));
  const auto hit = shapeCast(a, pose(Vec3(-3, 0, 0)), Vec3(3, 0, 0), b, pose(Vec3::Zero()), 2.0 / 3 + 1e-6);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->fraction, 2.0 / 3, kFraction);
  EXPECT_FALSE(shapeCast(ShapeDesc::plane(Vec3::UnitY(), 0), pose(Vec3::Zero()), Vec3(1, 0, 0), b, pose(Vec3::Zero())));
  EXPECT_FALSE(shapeCast(a, pose(Vec3(-3, 0, 0)), Vec3::Zero(), b, pose(Vec3::Zero())));
}

}  // namespace
}  // namespace cairn
