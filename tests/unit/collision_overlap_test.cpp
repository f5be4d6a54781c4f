// Overlap tests at separations of +-1e-6 around touching, for every target
// type and the sphere, box, capsule, cylinder and hull query shapes.
//
// Each case places the query shape exactly touching the target (a closed
// form: the gap along the separating direction is zero), then moves it 1e-6
// apart (no overlap) and 1e-6 together (overlap). GJK's distance is exact
// for polytope cores and relative to 1e-13 for a cylinder, so 1e-6 is
// 10^6 times what the test needs to resolve; touching exactly counts as
// overlapping (closed shapes).
#include "collision/mesh_bvh.hpp"
#include "collision/overlap.hpp"
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using test::pose;
using test::rotation;

// `query` at `touching` touches `target`; moving it along `away` separates.
void expectBoundaryAt(const ShapeDesc& query, const Transform& touching, const Vec3& away, const ShapeDesc& target,
                      const Transform& tt) {
  const Vec3 n = away.normalized();
  EXPECT_FALSE(overlaps(query, pose(touching.p + 1e-6 * n, touching.q), target, tt))
      << shapeTypeName(query.type) << " 1e-6 apart from " << shapeTypeName(target.type);
  EXPECT_TRUE(overlaps(query, pose(touching.p - 1e-6 * n, touching.q), target, tt))
      << shapeTypeName(query.type) << " 1e-6 into " << shapeTypeName(target.type);
}

TEST(Overlap, SpheresTouchingExactlyOverlapAndApartBy1e6DoNot) {
  const ShapeDesc a = ShapeDesc::sphere(0.5), b = ShapeDesc::sphere(0.25);
  EXPECT_TRUE(overlaps(a, pose(Vec3(0.75, 0, 0)), b, pose(Vec3::Zero())));  // exactly touching
  const Vec3 dir = Vec3(1, 2, -0.5).normalized();
  expectBoundaryAt(a, pose(Vec3(1, 1, 1) + 0.75 * dir), dir, b, pose(Vec3(1, 1, 1)));
  // A capsule target: the sphere against its cap, and against its side.
  const ShapeDesc cap = ShapeDesc::capsule(0.3, 0.6);
  const Transform tc = pose(Vec3(0, 1, 0), rotation(0.5, Vec3(0, 0, 1)));
  expectBoundaryAt(a, pose(tc.apply(Vec3(0, 0.6 + 0.8, 0)), rotation(0.3, Vec3::UnitX())), tc.q * Vec3::UnitY(), cap, tc);
  expectBoundaryAt(a, pose(tc.apply(Vec3(0.8, 0.2, 0))), tc.q * Vec3::UnitX(), cap, tc);
}

TEST(Overlap, RotatedBoxAtItsLowestCornerAboveABoxAndAPlane) {
  // Lowest corner of a box (rotation R, half extents h) centered at height
  // c_y: c_y - sum_i h_i |R_yi|; it touches when that equals the top.
  std::mt19937 rng(4);
  std::normal_distribution<Real> g(0, 1);
  const Vec3 h(0.3, 0.5, 0.2);
  const ShapeDesc box = ShapeDesc::box(h), ground = ShapeDesc::box(Vec3(4, 0.5, 4));
  const ShapeDesc plane = ShapeDesc::plane(Vec3(0, 2, 0), 0);  // y <= 0
  for (int i = 0; i < 20; ++i) {
    const Quat q = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    const Mat3 r = q.toRotationMatrix();
    const Real reach = h.dot(r.row(1).cwiseAbs().transpose());
    expectBoundaryAt(box, pose(Vec3(0.2, 0.5 + reach, -0.1), q), Vec3::UnitY(), ground, pose(Vec3::Zero()));
    expectBoundaryAt(box, pose(Vec3(0.2, reach, -0.1), q), Vec3::UnitY(), plane, pose(Vec3::Zero()));
  }
}

TEST(Overlap, CapsuleLyingOnABoxAndHullVertexOnATiltedPlane) {
  const ShapeDesc cap = ShapeDesc::capsule(0.2, 0.7);
  expectBoundaryAt(cap, pose(Vec3(0.3, 0.5 + 0.2, 0), rotation(kPi / 2, Vec3::UnitZ())), Vec3::UnitY(),
                   ShapeDesc::box(Vec3(2, 0.5, 2)), pose(Vec3::Zero()));
  // A hull touches a plane n.x <= e at its support point along -n.
  const ShapeDesc hull = test::blobHull();
  const Transform tp = pose(Vec3(0, -0.3, 0.1), rotation(0.4, Vec3(1, 0, 1)));
  const ShapeDesc plane = ShapeDesc::plane(Vec3::UnitY(), 0.2);
  Vec3 n;
  Real e;
  worldPlane(plane, tp, n, e);
  const Quat q = rotation(1.0, Vec3(0.2, 1, 0.4));
  const Vec3 deepest = supportWorld(hull, pose(Vec3::Zero(), q), -n);  // with the hull at the origin
  expectBoundaryAt(hull, pose(n * (e - n.dot(deepest)), q), n, plane, tp);
}

TEST(Overlap, CylinderCapsSidesAndCylinderQueries) {
  const ShapeDesc cyl = ShapeDesc::cylinder(0.5, 0.4);
  const Transform tc = pose(Vec3(1, 0, 0), rotation(0.3, Vec3(1, 1, 0)));
  const ShapeDesc sphere = ShapeDesc::sphere(0.25), box = ShapeDesc::box(Vec3(0.2, 0.3, 0.1));
  // A sphere over the cap, and beside the curved side.
  expectBoundaryAt(sphere, pose(tc.apply(Vec3(0.1, 0.65, 0.2))), tc.q * Vec3::UnitY(), cyl, tc);
  const Vec3 radial = Vec3(1, 0, -1).normalized();
  expectBoundaryAt(sphere, pose(tc.apply(0.75 * radial + Vec3(0, 0.1, 0))), tc.q * radial, cyl, tc);
  // A box face against the side: the two meet along a line.
  expectBoundaryAt(box, pose(tc.apply(Vec3(0.7, 0, 0)), tc.q), tc.q * Vec3::UnitX(), cyl, tc);
  // A cylinder as the query: standing on a box.
  expectBoundaryAt(cyl, pose(Vec3(0.2, 0.5 + 0.4, 0)), Vec3::UnitY(), ShapeDesc::box(Vec3(2, 0.5, 2)), pose(Vec3::Zero()));
}

TEST(Overlap, SphereAndBoxOnAMeshQuad) {
  const ShapeDesc mesh = test::quadMesh();
  const Transform tm = pose(Vec3(0.5, 1, 0), rotation(-0.3, Vec3(1, 0, 0)));
  expectBoundaryAt(ShapeDesc::sphere(0.3), pose(tm.apply(Vec3(0.4, 0.5, -0.6))), tm.q * Vec3::UnitY(), mesh, tm);
  // From below: triangles are two-sided.
  expectBoundaryAt(ShapeDesc::box(Vec3(0.2, 0.1, 0.3)), pose(tm.apply(Vec3(-0.2, 0.1, 0.3)), tm.q), tm.q * -Vec3::UnitY(),
                   mesh, tm);
  // Beyond the quad's edge: nothing.
  EXPECT_FALSE(overlaps(ShapeDesc::sphere(0.3), pose(tm.apply(Vec3(1.31, 0.2, 0))), mesh, tm));
}

TEST(Overlap, OnlyConvexShapesCanBeQueries) {
  const ShapeDesc plane = ShapeDesc::plane(Vec3::UnitY(), 0);
  EXPECT_FALSE(overlaps(plane, pose(Vec3::Zero()), ShapeDesc::sphere(1), pose(Vec3::Zero())));
  // A hull query shape overlapping a sphere deeply.
  EXPECT_TRUE(overlaps(test::cubeHull(0.5), pose(Vec3(0.3, 0, 0)), ShapeDesc::sphere(1), pose(Vec3::Zero())));
}

}  // namespace
}  // namespace cairn
