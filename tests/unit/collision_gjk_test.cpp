// GJK distance and EPA penetration against closed forms.
//
// Polytopes terminate exactly (a repeated support point), so box and hull
// results match to round-off (1e-12); smooth shapes converge to GJK's
// relative tolerance 1e-10 and EPA's 1e-8 of the size.
#include "collision/epa.hpp"
#include "collision/gjk.hpp"
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using test::pose;
using test::rotation;

TEST(Gjk, DistanceBetweenSeparatedBoxesIsExact) {
  const ShapeDesc box = ShapeDesc::box(Vec3(0.5, 0.5, 0.5));
  // Face to face along x: gap 2.
  const GjkResult r = gjkDistance(makeProxy(box, pose(Vec3::Zero())), makeProxy(box, pose(Vec3(3, 0.2, -0.1))), true);
  EXPECT_FALSE(r.overlap);
  EXPECT_NEAR(r.distance, 2, 1e-12);
  EXPECT_NEAR(r.point_a.x(), 0.5, 1e-12);
  EXPECT_NEAR(r.point_b.x(), 2.5, 1e-12);
  // Corner to corner: the second box turned so a corner points back at the
  // first's (0.5, 0.5, 0.5) corner along the diagonal.
  const Vec3 diag = Vec3(1, 1, 1).normalized();
  const Quat q = Quat::FromTwoVectors(Vec3(1, 1, 1).normalized(), -diag);
  const Real corner = std::sqrt(Real(3)) / 2;
  const GjkResult c = gjkDistance(makeProxy(box, pose(Vec3::Zero())), makeProxy(box, pose(diag * (2 * corner + 1), q)), true);
  EXPECT_NEAR(c.distance, 1, 1e-12);
}

TEST(Gjk, CoresAndRadii) {
  // Sphere cores are points: GJK on cores reports center distances.
  const ConvexProxy a = makeProxy(ShapeDesc::sphere(0.5), pose(Vec3::Zero()));
  const ConvexProxy b = makeProxy(ShapeDesc::capsule(0.25, 1), pose(Vec3(2, 0.3, 0)));
  const GjkResult core = gjkDistance(a, b, false);
  EXPECT_NEAR(core.distance, 2, 1e-12);  // to the capsule's segment
  const GjkResult full = gjkDistance(a, b, true);
  EXPECT_NEAR(full.distance, 2 - 0.75, 1e-9);  // rounded supports converge, not terminate
}

TEST(Gjk, EarlyOutBeyondMaxDistance) {
  const ShapeDesc box = ShapeDesc::box(Vec3::Constant(0.5));
  const GjkResult r = gjkDistance(makeProxy(box, pose(Vec3::Zero())), makeProxy(box, pose(Vec3(10, 0, 0))), true, 1.0);
  EXPECT_TRUE(r.beyond);
  EXPECT_GT(r.distance, 1.0);  // a lower bound that already exceeds the limit
  EXPECT_LT(r.iterations, 4);
}

TEST(Gjk, EpaDepthOfOverlappingBoxesMatchesTheLeastOverlapAxis) {
  const ShapeDesc a = ShapeDesc::box(Vec3(1, 0.5, 1));
  const ShapeDesc b = ShapeDesc::box(Vec3(0.5, 0.5, 0.5));
  const ConvexProxy pa = makeProxy(a, pose(Vec3::Zero()));
  const ConvexProxy pb = makeProxy(b, pose(Vec3(0.3, 0.8, -0.2), rotation(0.3, Vec3::UnitY())));
  const GjkResult g = gjkDistance(pa, pb, true);
  ASSERT_TRUE(g.overlap);
  const EpaResult e = epaPenetration(pa, pb, true, g.simplex);
  ASSERT_TRUE(e.ok);
  EXPECT_NEAR(e.depth, 0.2, 1e-12);  // along +y: 0.5 + 0.5 - 0.8
  EXPECT_LT((e.normal - Vec3::UnitY()).norm(), 1e-12);
  // The witness points are A's top face and B's bottom face, 0.2 apart.
  EXPECT_NEAR(e.point_a.y(), 0.5, 1e-12);
  EXPECT_NEAR(e.point_b.y(), 0.3, 1e-12);
}

TEST(Gjk, EpaOnCurvedShapesConvergesToTheClosedForm) {
  // A sphere's center 0.1 inside a cylinder's side, far from the caps:
  // depth r + 0.1 through the side.
  const ShapeDesc ball = ShapeDesc::sphere(0.3);
  const ShapeDesc cyl = ShapeDesc::cylinder(0.5, 2);
  const ConvexProxy pa = makeProxy(ball, pose(Vec3(0.4, 0.2, 0)));
  const ConvexProxy pb = makeProxy(cyl, pose(Vec3::Zero()));
  const GjkResult g = gjkDistance(pa, pb, false);
  ASSERT_TRUE(g.overlap);
  const EpaResult e = epaPenetration(pa, pb, false, g.simplex);
  ASSERT_TRUE(e.ok);
  EXPECT_NEAR(e.depth, 0.1, 1e-7);  // of the cores; the radius adds 0.3
  EXPECT_LT((e.normal + Vec3::UnitX()).norm(), 1e-3);  // A is pushed out through +x: B moves -x
}

TEST(Gjk, EpaFailsCleanlyWhenTheDifferenceIsFlat) {
  // A point on a triangle: A - B has no volume, EPA says so instead of
  // returning garbage (the narrowphase then uses the rounded shapes).
  const ConvexProxy p = makeProxy(ShapeDesc::sphere(0.1), pose(Vec3(0.2, 0, 0.2)));
  const ConvexProxy t = makeTriangleProxy(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 1));
  const GjkResult g = gjkDistance(p, t, false);
  ASSERT_TRUE(g.overlap);
  EXPECT_FALSE(epaPenetration(p, t, false, g.simplex).ok);
  const GjkResult gf = gjkDistance(p, t, true);
  const EpaResult e = epaPenetration(p, t, true, gf.simplex);
  ASSERT_TRUE(e.ok);
  EXPECT_NEAR(e.depth, 0.1, 1e-7);
  EXPECT_NEAR(std::abs(e.normal.y()), 1, 1e-6);
}

}  // namespace
}  // namespace cairn
