// Convex hull construction (qhull) and its invariants.
#include "collision/hull.hpp"
#include "cairn/error.hpp"
#include "dynamics/mass_properties.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace cairn {
namespace {

std::vector<Vec3> unitCubeCorners() {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.emplace_back(i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5);
  return p;
}

// Every face loop must be planar, counter-clockwise seen from outside (its
// Newell normal agrees with the stored outward normal) and every hull vertex
// must lie behind every face plane. Tolerance 1e-12: coordinates are O(1) and
// each check is a handful of round-off-level operations.
void expectWellFormed(const ConvexHullData& h) {
  ASSERT_EQ(h.faces.size(), h.face_normals.size());
  ASSERT_EQ(h.faces.size(), h.face_offsets.size());
  for (size_t f = 0; f < h.faces.size(); ++f) {
    const auto& loop = h.faces[f];
    const Vec3 n = h.face_normals[f];
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    Vec3 newell = Vec3::Zero();
    for (size_t k = 0; k < loop.size(); ++k) {
      const Vec3& a = h.vertices[loop[k]];
      const Vec3& b = h.vertices[loop[(k + 1) % loop.size()]];
      newell += a.cross(b);
      EXPECT_NEAR(n.dot(a), h.face_offsets[f], 1e-12) << "face " << f << " not planar";
    }
    EXPECT_GT(newell.dot(n), 0) << "face " << f << " is not counter-clockwise from outside";
    for (const Vec3& v : h.vertices) EXPECT_LE(n.dot(v), h.face_offsets[f] + 1e-12);
  }
  // Euler's formula for a convex polyhedron: V - E + F = 2.
  EXPECT_EQ(int(h.vertices.size()) - int(h.edges.size()) + int(h.faces.size()), 2);
}

TEST(Hull, CubeCornersWithInteriorPointsGiveEightVerticesSixFaces) {
  std::vector<Vec3> pts = unitCubeCorners();
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-0.45, 0.45);
  for (int i = 0; i < 50; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  pts.emplace_back(0.5, 0, 0);  // on a face: coplanar, not a vertex
  const auto hull = buildConvexHull(pts);
  EXPECT_EQ(hull->vertices.size(), 8u);
  EXPECT_EQ(hull->faces.size(), 6u);
  EXPECT_EQ(hull->edges.size(), 12u);
  for (const auto& f : hull->faces) EXPECT_EQ(f.size(), 4u);
  expectWellFormed(*hull);
  ShapeDesc s;
  s.type = ShapeType::ConvexHull;
  s.hull = hull;
  // The volume sums exact tetrahedra: only round-off separates it from 1.
  EXPECT_NEAR(shapeMassProperties(s, 1).mass, 1.0, 1e-12);
  EXPECT_LT(shapeMassProperties(s, 1).center.norm(), 1e-12);
}

TEST(Hull, RandomCloudIsWellFormedAndEnclosesAllPoints) {
  std::mt19937 rng(11);
  std::normal_distribution<Real> g(0, 1);
  std::vector<Vec3> pts;
  for (int i = 0; i < 200; ++i) pts.emplace_back(g(rng), 0.5 * g(rng), 2 * g(rng));
  const auto hull = buildConvexHull(pts);
  expectWellFormed(*hull);
  for (const Vec3& p : pts)
    for (size_t f = 0; f < hull->faces.size(); ++f) EXPECT_LE(hull->face_normals[f].dot(p), hull->face_offsets[f] + 1e-9);
}

TEST(Hull, CoplanarPointsAreRejected) {
  std::vector<Vec3> pts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.3, 0.2, 0}};
  try {
    buildConvexHull(pts, "body 'slab'", "shapes[0].points");
    FAIL() << "coplanar points accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "body 'slab'");
    EXPECT_EQ(e.field(), "shapes[0].points");
    EXPECT_NE(e.message().find("coplanar"), std::string::npos) << e.what();
  }
  // Colinear and all-identical clouds are flat too.
  EXPECT_THROW(buildConvexHull({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}), InputError);
  EXPECT_THROW(buildConvexHull({{1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}}), InputError);
}

TEST(Hull, FewerThanFourPointsAreRejected) {
  EXPECT_THROW(buildConvexHull({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}), InputError);
}

TEST(Hull, NonFinitePointIsRejectedByIndex) {
  std::vector<Vec3> pts = unitCubeCorners();
  pts[3].y() = std::nan("");
  try {
    buildConvexHull(pts, "body 'rock'", "points");
    FAIL() << "NaN accepted";
  } catch (const InputError& e) {
    EXPECT_NE(e.message().find("points[3] is not finite"), std::string::npos) << e.what();
  }
}

// A hull far from its shape's origin has the mass properties of the same
// hull at the origin, moved: the sums are taken about the hull's own
// vertex mean. About the far origin, a 0.1 m box 10 km out lost every digit
// of its volume (tetrahedra of 1e12 m^3 summing to 1e-3 m^3) and was
// refused as "degenerate inertia".
TEST(Hull, FarFromTheOriginHasTheMassPropertiesOfTheSameHullNearIt) {
  for (const Real far : {Real(1e4), Real(1e7)}) {
    std::vector<Vec3> pts;
    for (const Vec3& c : unitCubeCorners()) pts.push_back(Vec3(far, -far, 2 * far) + Real(0.1) * c);
    ShapeDesc s;
    s.type = ShapeType::ConvexHull;
    s.hull = buildConvexHull(pts);
    const MassProperties mp = shapeMassProperties(s, 1000);
    // Box of side 0.1: m = 1000 x 1e-3 = 1 kg, I = m/6 a^2 on each axis.
    // The corners are rounded to the ulp of the offset (2e-12 at 1e4,
    // 2e-9 at 1e7), a relative error of 2e-11 or 2e-8 in a 0.1 m side;
    // the tolerances are ten times those, times the power of the side in
    // each quantity.
    const Real rel = Real(10) * std::numeric_limits<Real>::epsilon() * far / Real(0.1);
    EXPECT_NEAR(mp.mass, 1.0, 3 * rel) << far;
    EXPECT_NEAR((mp.center - Vec3(far, -far, 2 * far)).norm(), 0, 2 * far * std::numeric_limits<Real>::epsilon()) << far;
    const Real i = Real(1) / 6 * Real(0.01);
    EXPECT_TRUE(mp.inertia.isApprox(i * Mat3::Identity(), 5 * rel)) << far << "\n" << mp.inertia;
  }
}

TEST(Hull, MorePointsThanTheLimitAreRefusedBeforeQhullRuns) {
  InputLimits limits;
  limits.hull_points = 7;
  try {
    buildConvexHull(unitCubeCorners(), "body 'rock'", "shapes[0].points", limits);
    FAIL() << "accepted 8 points with a limit of 7";
  } catch (const InputError& e) {
    EXPECT_NE(e.message().find("8 points exceed the limit (limit hull_points = 7"), std::string::npos) << e.what();
  }
  limits.hull_points = 8;
  EXPECT_EQ(buildConvexHull(unitCubeCorners(), "", "points", limits)->vertices.size(), 8u);
}

}  // namespace
}  // namespace cairn
