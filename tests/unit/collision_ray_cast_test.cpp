// Ray casts against every shape type, checked against closed forms.
//
// Each case is set up in the shape's frame, where the answer is known, and
// then placed at a rotated, translated pose: the fraction must not change
// and the normal must turn with the shape. The closed forms evaluated here
// are a handful of operations, so fractions match to 1e-12 (a few hundred
// ulps of the inputs, which are of order 1-10) unless stated otherwise.
#include "collision/mesh_bvh.hpp"
#include "collision/ray_cast.hpp"
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using test::pose;
using test::rotation;

constexpr Real kExact = 1e-12;

const Transform kTilted = pose(Vec3(0.3, -1.2, 2.5), rotation(0.7, Vec3(1, 2, -0.5)));

// Casts a ray given in the shape's frame of `t`.
std::optional<CastHit> castLocal(const ShapeDesc& s, const Transform& t, const Vec3& o_local, const Vec3& d_local) {
  return rayCast(s, t, t.apply(o_local), t.q * d_local);
}

void expectVecNear(const Vec3& a, const Vec3& b, Real tol) {
  EXPECT_LE((a - b).norm(), tol) << "got " << a.transpose() << ", want " << b.transpose();
}

TEST(RayCastSphere, DownwardRayHitsAtHeightMinusRadiusOverLength) {
  const Real r = 0.75, h = 4.0, L = 10.0;
  const Vec3 c(0.3, -0.2, 0.1);
  const auto hit = rayCast(ShapeDesc::sphere(r), pose(c), c + Vec3(0, h, 0), Vec3(0, -L, 0));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->fraction, (h - r) / L, kExact);
  expectVecNear(hit->normal, Vec3::UnitY(), kExact);
  expectVecNear(hit->point, c + Vec3(0, r, 0), kExact);
  EXPECT_FALSE(hit->inside);
  EXPECT_EQ(hit->triangle, -1);
}

TEST(RayCastSphere, TangentRayGrazesAndAnEpsilonHigherMisses) {
  // b^2 - a c is exactly 0 for these inputs: the tangent touches.
  const ShapeDesc s = ShapeDesc::sphere(1);
  const auto graze = rayCast(s, pose(Vec3::Zero()), Vec3(-5, 1, 0), Vec3(10, 0, 0));
  ASSERT_TRUE(graze);
  EXPECT_NEAR(graze->fraction, 0.5, kExact);
  expectVecNear(graze->normal, Vec3::UnitY(), kExact);
  EXPECT_FALSE(rayCast(s, pose(Vec3::Zero()), Vec3(-5, 1 + 1e-9, 0), Vec3(10, 0, 0)));
  // Just below the tangent: the chord's entry x = -sqrt(1 - y^2).
  const Real y = 1 - 1e-6;
  const auto near = rayCast(s, pose(Vec3::Zero()), Vec3(-5, y, 0), Vec3(10, 0, 0));
  ASSERT_TRUE(near);
  EXPECT_NEAR(near->fraction, (5 - std::sqrt(1 - y * y)) / 10, kExact);
}

TEST(RayCastSphere, SegmentEndingShortOfTheSurfaceMissesAndEndingOnItHitsAtOne) {
  const ShapeDesc s = ShapeDesc::sphere(0.5);
  EXPECT_FALSE(rayCast(s, pose(Vec3::Zero()), Vec3(0, 3, 0), Vec3(0, -2.5 + 1e-9, 0)));
  const auto hit = rayCast(s, pose(Vec3::Zero()), Vec3(0, 3, 0), Vec3(0, -2.5, 0));
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->fraction, 1);
  // A ray pointing away never hits, however long.
  EXPECT_FALSE(rayCast(s, pose(Vec3::Zero()), Vec3(0, 3, 0), Vec3(0, 100, 0)));
}

TEST(RayCastSphere, StartInsideHitsAtZeroFacingTheRay) {
  const auto hit = rayCast(ShapeDesc::sphere(1), pose(Vec3(1, 1, 1)), Vec3(1.2, 1.1, 0.9), Vec3(0, 0, 4));
  ASSERT_TRUE(hit);
  EXPECT_TRUE(hit->inside);
  EXPECT_EQ(hit->fraction, 0);
  expectVecNear(hit->point, Vec3(1.2, 1.1, 0.9), 0);
  expectVecNear(hit->normal, -Vec3::UnitZ(), kExact);
}

TEST(RayCastSphere, StartOnSurfaceHitsOnlyWhenMovingIn) {
  const ShapeDesc s = ShapeDesc::sphere(2);
  const auto in = rayCast(s, pose(Vec3::Zero()), Vec3(0, 2, 0), Vec3(0.1, -1, 0));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->fraction, 0);
  EXPECT_FALSE(in->inside);
  expectVecNear(in->normal, Vec3::UnitY(), kExact);
  EXPECT_FALSE(rayCast(s, pose(Vec3::Zero()), Vec3(0, 2, 0), Vec3(0.1, 1, 0)));  // out
  EXPECT_FALSE(rayCast(s, pose(Vec3::Zero()), Vec3(0, 2, 0), Vec3(1, 0, 0)));    // along the tangent
}

TEST(RayCastAnyShape, ZeroTranslationCastsNothing) {
  EXPECT_FALSE(rayCast(ShapeDesc::sphere(1), pose(Vec3::Zero()), Vec3::Zero(), Vec3::Zero()));
  EXPECT_FALSE(rayCast(ShapeDesc::box(Vec3::Ones()), pose(Vec3::Zero()), Vec3(0, 5, 0), Vec3::Zero()));
}

TEST(RayCastBox, RotatedBoxMatchesTheSlabAnswerInItsFrame) {
  const Vec3 h(0.5, 0.25, 1.0);
  const ShapeDesc box = ShapeDesc::box(h);
  // Straight at the -x face.
  const auto a = castLocal(box, kTilted, Vec3(-3, 0.2, 0.1), Vec3(6, 0, 0));
  ASSERT_TRUE(a);
  EXPECT_NEAR(a->fraction, (3 - 0.5) / 6, kExact);
  expectVecNear(a->normal, kTilted.q * -Vec3::UnitX(), kExact);
  // Obliquely at a point P of the +y face: from P + e along -1.6 e.
  const Vec3 p(0.1, h.y(), -0.2), e(0.5, 2, 0.3);
  const auto b = castLocal(box, kTilted, p + e, -1.6 * e);
  ASSERT_TRUE(b);
  EXPECT_NEAR(b->fraction, 1 / 1.6, kExact);
  expectVecNear(b->normal, kTilted.q * Vec3::UnitY(), kExact);
  expectVecNear(b->point, kTilted.apply(p), 1e-11);
}

TEST(RayCastBox, RayParallelToFacesHitsInsideTheSlabAndMissesJustOutside) {
  const ShapeDesc box = ShapeDesc::box(Vec3(1, 1, 1));
  // Along the plane of the top face, y = 1 exactly: the closed slab holds it,
  // the ray meets the box's top edge on the -x face. (Unrotated: a rotation
  // would leave a round-off component across the slab, and which side of
  // the plane the ray then lies on is round-off too.)
  const auto edge = rayCast(box, pose(Vec3::Zero()), Vec3(-4, 1, 0.3), Vec3(8, 0, 0));
  ASSERT_TRUE(edge);
  EXPECT_NEAR(edge->fraction, 3.0 / 8, kExact);
  expectVecNear(edge->normal, -Vec3::UnitX(), 0);
  EXPECT_FALSE(rayCast(box, pose(Vec3::Zero()), Vec3(-4, 1 + 1e-12, 0.3), Vec3(8, 0, 0)));
  EXPECT_FALSE(rayCast(box, pose(Vec3::Zero()), Vec3(-4, 0.2, -1 - 1e-12), Vec3(8, 0, 0)));
  // Parallel to two axes at once, well inside both slabs.
  const auto mid = rayCast(box, pose(Vec3::Zero()), Vec3(0.2, -0.4, 6), Vec3(0, 0, -10));
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->fraction, 0.5, kExact);
  expectVecNear(mid->normal, Vec3::UnitZ(), 0);
}

TEST(RayCastBox, StartInsideHitsAtZeroAndStartOnAFaceHitsOnlyGoingIn) {
  const ShapeDesc box = ShapeDesc::box(Vec3(1, 2, 3));
  const auto inside = castLocal(box, kTilted, Vec3(0.9, -1.9, 2.9), Vec3(5, 0, 0));
  ASSERT_TRUE(inside);
  EXPECT_TRUE(inside->inside);
  EXPECT_EQ(inside->fraction, 0);
  expectVecNear(inside->normal, kTilted.q * -Vec3::UnitX(), kExact);
  const auto in = rayCast(box, pose(Vec3::Zero()), Vec3(0.5, 2, 0), Vec3(0, -1, 0.2));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->fraction, 0);
  EXPECT_FALSE(in->inside);
  expectVecNear(in->normal, Vec3::UnitY(), 0);
  EXPECT_FALSE(rayCast(box, pose(Vec3::Zero()), Vec3(0.5, 2, 0), Vec3(0, 1, 0.2)));  // leaving
  EXPECT_FALSE(rayCast(box, pose(Vec3::Zero()), Vec3(0.5, 2, 0), Vec3(1, 0, 0.2)));  // sliding along the face
}

TEST(RayCastCapsule, SideCapAndRotatedCapsuleMatchClosedForms) {
  const Real r = 0.4, hh = 0.8;
  const ShapeDesc cap = ShapeDesc::capsule(r, hh);
  // Side: horizontal toward the axis at y = 0.5 (|y| < hh): enters at radius r.
  const auto side = castLocal(cap, kTilted, Vec3(3, 0.5, 0), Vec3(-6, 0, 0));
  ASSERT_TRUE(side);
  EXPECT_NEAR(side->fraction, (3 - r) / 6, kExact);
  expectVecNear(side->normal, kTilted.q * Vec3::UnitX(), kExact);
  // Cap, on the axis: the top of the cap sphere at y = hh + r.
  const auto top = castLocal(cap, kTilted, Vec3(0, 5, 0), Vec3(0, -10, 0));
  ASSERT_TRUE(top);
  EXPECT_NEAR(top->fraction, (5 - hh - r) / 10, kExact);
  expectVecNear(top->normal, kTilted.q * Vec3::UnitY(), kExact);
  // Cap, off the axis at x: y = hh + sqrt(r^2 - x^2), normal (x, y - hh, 0) / r.
  const Real x = 0.3, y = hh + std::sqrt(r * r - x * x);
  const auto off = castLocal(cap, kTilted, Vec3(x, -5, 0), Vec3(0, 20, 0));
  ASSERT_TRUE(off);  // from below: the bottom cap, mirrored
  EXPECT_NEAR(off->fraction, (5 - y) / 20, kExact);
  expectVecNear(off->normal, kTilted.q * Vec3(x, -(y - hh), 0) / r, kExact);
  // Just outside the cylinder part: misses.
  EXPECT_FALSE(rayCast(cap, pose(Vec3::Zero()), Vec3(-3, 0.2, r + 1e-9), Vec3(6, 0, 0)));
}

TEST(RayCastCapsule, StartInsideEitherCapOrTheMiddleHitsAtZero) {
  const ShapeDesc cap = ShapeDesc::capsule(0.5, 1);
  for (const Vec3& o : {Vec3(0, 1.45, 0), Vec3(0.45, 0, 0), Vec3(0.1, -1.3, 0.2)}) {
    const auto hit = rayCast(cap, pose(Vec3::Zero()), o, Vec3(0, 0, 1));
    ASSERT_TRUE(hit);
    EXPECT_TRUE(hit->inside);
    EXPECT_EQ(hit->fraction, 0);
  }
}

TEST(RayCastCylinder, SideCapRimAndRotatedCylinderMatchClosedForms) {
  const Real r = 0.5, hh = 1.0;
  const ShapeDesc cyl = ShapeDesc::cylinder(r, hh);
  const auto side = castLocal(cyl, kTilted, Vec3(0, 0.9, -4), Vec3(0, 0, 8));
  ASSERT_TRUE(side);
  EXPECT_NEAR(side->fraction, (4 - r) / 8, kExact);
  expectVecNear(side->normal, kTilted.q * -Vec3::UnitZ(), kExact);
  const auto cap = castLocal(cyl, kTilted, Vec3(0.45, 3, 0), Vec3(0, -4, 0));
  ASSERT_TRUE(cap);
  EXPECT_NEAR(cap->fraction, (3 - hh) / 4, kExact);
  expectVecNear(cap->normal, kTilted.q * Vec3::UnitY(), kExact);
  const auto bottom = castLocal(cyl, kTilted, Vec3(0, -3, 0.2), Vec3(0, 4, 0));
  ASSERT_TRUE(bottom);
  EXPECT_NEAR(bottom->fraction, (3 - hh) / 4, kExact);
  expectVecNear(bottom->normal, kTilted.q * -Vec3::UnitY(), kExact);
  // Straight down through the rim (x = r): the closed cap disc holds it.
  const auto rim = rayCast(cyl, pose(Vec3::Zero()), Vec3(r, 3, 0), Vec3(0, -4, 0));
  ASSERT_TRUE(rim);
  EXPECT_NEAR(rim->fraction, (3 - hh) / 4, kExact);
  EXPECT_FALSE(rayCast(cyl, pose(Vec3::Zero()), Vec3(r + 1e-9, 3, 0), Vec3(0, -4, 0)));
  // Horizontally along the plane of the top cap: meets the side at the rim.
  const auto along = rayCast(cyl, pose(Vec3::Zero()), Vec3(-4, hh, 0), Vec3(8, 0, 0));
  ASSERT_TRUE(along);
  EXPECT_NEAR(along->fraction, (4 - r) / 8, kExact);
  EXPECT_FALSE(rayCast(cyl, pose(Vec3::Zero()), Vec3(-4, hh + 1e-12, 0), Vec3(8, 0, 0)));
  // Obliquely into the side: enters where x^2 + z^2 = r^2 along the ray.
  const Vec3 o(-2, 0.1, 0.3), d(4, 0.2, 0);
  const Real f = (-o.x() - std::sqrt(r * r - o.z() * o.z())) / d.x();
  const auto oblique = rayCast(cyl, pose(Vec3::Zero()), o, d);
  ASSERT_TRUE(oblique);
  EXPECT_NEAR(oblique->fraction, f, kExact);
  const auto inside = rayCast(cyl, pose(Vec3::Zero()), Vec3(0.1, 0.99, 0.1), Vec3(1, 0, 0));
  ASSERT_TRUE(inside);
  EXPECT_TRUE(inside->inside);
}

TEST(RayCastPlane, HitsAtHeightOverSpeedWithAnyNormalScaleOrPose) {
  // 2 y <= 2 is the half-space y <= 1.
  const ShapeDesc plane = ShapeDesc::plane(Vec3(0, 2, 0), 2);
  const auto down = rayCast(plane, pose(Vec3::Zero()), Vec3(0.3, 5, 0.1), Vec3(1, -8, 0));
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->fraction, 4.0 / 8, kExact);
  expectVecNear(down->normal, Vec3::UnitY(), 0);
  // The same plane tilted by the pose, ray given in its frame.
  const auto tilted = castLocal(plane, kTilted, Vec3(0.3, 5, 0.1), Vec3(1, -8, 0));
  ASSERT_TRUE(tilted);
  EXPECT_NEAR(tilted->fraction, 0.5, kExact);
  expectVecNear(tilted->normal, kTilted.q * Vec3::UnitY(), kExact);
  EXPECT_FALSE(rayCast(plane, pose(Vec3::Zero()), Vec3(0, 5, 0), Vec3(100, 0, 0)));  // parallel
  EXPECT_FALSE(rayCast(plane, pose(Vec3::Zero()), Vec3(0, 1, 0), Vec3(0, 1, 0)));   // on it, leaving
  const auto below = rayCast(plane, pose(Vec3::Zero()), Vec3(0, 0.5, 0), Vec3(0, 1, 0));
  ASSERT_TRUE(below);
  EXPECT_TRUE(below->inside);
  expectVecNear(below->normal, -Vec3::UnitY(), 0);
}

TEST(RayCastHull, CubeHullAgreesWithTheBoxForRandomRays) {
  // Independent code paths (face planes from the hull builder vs slabs): a
  // cube's face planes are exact, so the answers agree to round-off.
  const ShapeDesc hull = test::cubeHull(0.5);
  const ShapeDesc box = ShapeDesc::box(Vec3::Constant(0.5));
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 500; ++i) {
    // Half the rays aimed at points inside the cube, half anywhere.
    const Vec3 o = 2 * Vec3(u(rng), u(rng), u(rng)), target = (i % 2 ? 0.45 : 2.0) * Vec3(u(rng), u(rng), u(rng));
    const Vec3 d = 1.5 * (target - o);
    const auto a = rayCast(hull, kTilted, kTilted.apply(o), kTilted.q * d);
    const auto b = rayCast(box, kTilted, kTilted.apply(o), kTilted.q * d);
    ASSERT_EQ(a.has_value(), b.has_value()) << i;
    if (!a) continue;
    ++hits;
    EXPECT_EQ(a->inside, b->inside);
    EXPECT_NEAR(a->fraction, b->fraction, kExact);
    expectVecNear(a->normal, b->normal, kExact);
  }
  EXPECT_GT(hits, 250);
}

TEST(RayCastHull, IrregularHullHitPointIsOnTheSurfaceAndFirst) {
  // The hull's signed distance (largest face-plane distance) is exact on the
  // surface: the hit point has distance 0 to round-off, a point 1e-7 of the
  // segment earlier is outside, and the normal is the face attaining it.
  const ShapeDesc hull = test::blobHull();
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 300; ++i) {
    const Vec3 o = 1.5 * Vec3(u(rng), u(rng), u(rng)).normalized(), target = 0.3 * Vec3(u(rng), u(rng), u(rng));
    const Vec3 d = 1.2 * (target - o);
    const auto hit = rayCast(hull, kTilted, kTilted.apply(o), kTilted.q * d);
    // From outside toward a point inside, the segment (1.2 times as long)
    // must enter; toward a point outside it may or may not.
    ASSERT_GT(test::signedDistance(hull, pose(Vec3::Zero()), o), 0);
    if (test::signedDistance(hull, pose(Vec3::Zero()), target) < 0) {
      ASSERT_TRUE(hit) << i;
    }
    if (!hit) continue;
    ++hits;
    EXPECT_NEAR(test::signedDistance(hull, kTilted, hit->point), 0, kExact);
    EXPECT_GT(test::signedDistance(hull, kTilted, hit->point - 1e-7 * (kTilted.q * d)), 0);
    const Vec3 n_local = kTilted.q.conjugate() * hit->normal;
    Real best = -kInf;
    const Vec3 p_local = kTilted.applyInverse(hit->point);
    for (size_t k = 0; k < hull.hull->face_normals.size(); ++k)
      best = std::max(best, hull.hull->face_normals[k].dot(p_local) - hull.hull->face_offsets[k]);
    // The normal is the plane of a face through the hit point (on an edge
    // two faces pass through it; either is an outward normal) and faces
    // the ray.
    int through = 0;
    for (size_t k = 0; k < hull.hull->face_normals.size(); ++k)
      if ((hull.hull->face_normals[k] - n_local).norm() < kExact &&
          std::abs(hull.hull->face_normals[k].dot(p_local) - hull.hull->face_offsets[k]) < kExact)
        ++through;
    EXPECT_EQ(through, 1) << i;
    EXPECT_NEAR(best, 0, kExact);
    EXPECT_LT(n_local.dot(d), 0);
  }
  EXPECT_GT(hits, 200);
}

TEST(RayCastMesh, RayDownOntoAQuadHitsTheRightTriangleFacingTheRay) {
  const ShapeDesc mesh = test::quadMesh();
  // (x, z) = (0.3, -0.4): x > z, the triangle (0, 2, 3).
  const auto down = castLocal(mesh, kTilted, Vec3(0.3, 1.2, -0.4), Vec3(0, -2, 0));
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->fraction, 0.5, kExact);
  EXPECT_EQ(down->triangle, 1);
  expectVecNear(down->normal, kTilted.q * Vec3::UnitY(), kExact);
  // From below the two-sided triangle faces the ray: -y.
  const auto up = castLocal(mesh, kTilted, Vec3(-0.3, -0.8, 0.4), Vec3(0, 4, 0));
  ASSERT_TRUE(up);
  EXPECT_NEAR(up->fraction, 0.25, kExact);
  EXPECT_EQ(up->triangle, 0);
  expectVecNear(up->normal, kTilted.q * -Vec3::UnitY(), kExact);
  // Through the shared diagonal: both triangles at the same fraction; the
  // lower index is reported.
  const auto diag = rayCast(mesh, pose(Vec3::Zero()), Vec3(0.25, 1.2, 0.25), Vec3(0, -2, 0));
  ASSERT_TRUE(diag);
  EXPECT_EQ(diag->triangle, 0);
  // In the triangles' plane, or starting on them: no hit (no thickness).
  EXPECT_FALSE(rayCast(mesh, pose(Vec3::Zero()), Vec3(-3, 0.2, 0.1), Vec3(6, 0, 0)));
  EXPECT_FALSE(rayCast(mesh, pose(Vec3::Zero()), Vec3(0.1, 0.2, 0.5), Vec3(0, 1, 0)));
  // Past the edge by 1e-9: miss.
  EXPECT_FALSE(rayCast(mesh, pose(Vec3::Zero()), Vec3(1 + 1e-9, 1, 0), Vec3(0, -2, 0)));
}

TEST(RayCastMesh, BvhWalkFindsTheSameFirstTriangleAsTestingEveryTriangle) {
  // The 3200-triangle terrain of the mesh tests, with and without its tree.
  const ShapeDesc with = test::meshShape(test::bumpyTerrain(40, 4, 0.2, true));
  const ShapeDesc without = test::meshShape(test::bumpyTerrain(40, 4, 0.2, false));
  const TriangleMeshData& m = *with.mesh;
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> u(-1, 1);
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 o(5 * u(rng), 1 + u(rng), 5 * u(rng)), target(4 * u(rng), 0.3 * u(rng), 4 * u(rng));
    const Vec3 d = 1.5 * (target - o);
    // Brute force: every triangle, lowest fraction, then lowest index.
    Real best = kInf;
    int best_t = -1;
    for (int t = 0; t < static_cast<int>(m.triangles.size()); ++t) {
      const auto& tri = m.triangles[t];
      const auto f = rayTriangle(m.vertices[tri[0]], m.vertices[tri[1]], m.vertices[tri[2]], o, d, 1);
      if (f && *f < best) best = *f, best_t = t;
    }
    const auto a = rayCast(with, kTilted, kTilted.apply(o), kTilted.q * d);
    const auto b = rayCast(without, kTilted, kTilted.apply(o), kTilted.q * d);
    ASSERT_EQ(a.has_value(), best_t >= 0) << i;
    ASSERT_EQ(b.has_value(), best_t >= 0) << i;
    if (!a) continue;
    ++hits;
    EXPECT_EQ(a->triangle, best_t);
    EXPECT_EQ(b->triangle, best_t);
    EXPECT_NEAR(a->fraction, best, kExact);
    EXPECT_EQ(a->fraction, b->fraction);
  }
  EXPECT_GT(hits, 300);
}

}  // namespace
}  // namespace cairn
