// The World's queries (World::castRay, castRayAll, castShape, overlap)
// through its public face, against closed forms for every shape type: a
// world of one body per shape type, each hit at a point worked out by hand.
//
// Tolerances: ray casts against spheres, boxes, capsules, cylinders,
// planes, hull planes and triangles are closed forms evaluated in double,
// so fractions and points agree to round-off of the O(10) m coordinates
// (1e-12). Shape casts run GJK on the cores, which stops within 1e-10 of
// the shapes' size (collision/gjk_raycast.hpp): fractions to 1e-9.
#include "cairn/error.hpp"
#include "cairn/world.hpp"
#include "collision_test_shapes.hpp"
#include "test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace cairn {
namespace {

constexpr Real kExact = 1e-12;
constexpr Real kGjk = 1e-9;

BodyDef staticBody(const std::string& name, const Vec3& p, const ShapeDesc& s, const Quat& q = Quat::Identity()) {
  BodyDef d;
  d.name = name;
  d.type = BodyType::Static;
  d.position = p;
  d.orientation = q;
  d.shapes.push_back(s);
  return d;
}

// One body per shape type along x, over a ground plane y = 0; the sphere
// is dynamic (for the type filters), the rest static. Nothing is stepped.
struct ShapeRow {
  World world;
  BodyId ground, sphere, box, capsule, cylinder, hull, mesh;
  ShapeRow() {
    ground = world.createBody(staticBody("ground", Vec3::Zero(), ShapeDesc::plane(Vec3::UnitY(), 0)));
    BodyDef s = test::sphereDef("sphere", Vec3(0, 1, 0), 1, 0.5);
    sphere = world.createBody(s);
    box = world.createBody(staticBody("box", Vec3(3, 1, 0), ShapeDesc::box(Vec3(0.5, 0.25, 0.5)),
                                      test::rotation(kPi / 6, Vec3::UnitY())));
    capsule = world.createBody(staticBody("capsule", Vec3(6, 1, 0), ShapeDesc::capsule(0.3, 0.5)));
    cylinder = world.createBody(staticBody("cylinder", Vec3(9, 1, 0), ShapeDesc::cylinder(0.4, 0.3)));
    hull = world.createBody(staticBody("hull", Vec3(12, 1, 0), test::cubeHull(0.5)));
    mesh = world.createBody(staticBody("mesh", Vec3(15, 0, 0), test::quadMesh()));
  }
  ShapeId shapeOf(BodyId b) const { return world.shapes(b)[0]; }
};

void expectHit(const std::optional<RayHit>& h, BodyId body, ShapeId shape, Real fraction, const Vec3& point,
               const Vec3& normal) {
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->body, body);
  EXPECT_EQ(h->shape, shape);
  EXPECT_NEAR(h->fraction, fraction, kExact);
  EXPECT_LT((h->point - point).norm(), kExact) << h->point.transpose();
  EXPECT_LT((h->normal - normal).norm(), kExact) << h->normal.transpose();
}

TEST(WorldQueries, RayHitsEveryShapeTypeWhereTheClosedFormSays) {
  const ShapeRow r;
  const Vec3 down(0, -10, 0);
  // Sphere: x = 0.3 meets |p - c| = 0.5 at y = 1 + sqrt(0.25 - 0.09) = 1.4.
  expectHit(r.world.castRay(Vec3(0.3, 5, 0), down), r.sphere, r.shapeOf(r.sphere), 0.36, Vec3(0.3, 1.4, 0),
            Vec3(0.6, 0.8, 0));
  // Box turned about y: its top face stays at y = 1.25.
  expectHit(r.world.castRay(Vec3(3.1, 5, 0.2), down), r.box, r.shapeOf(r.box), 0.375, Vec3(3.1, 1.25, 0.2),
            Vec3::UnitY());
  // Capsule side (radius 0.3 about the y axis) from +z, then its top cap:
  // the sphere of 0.3 about (6, 1.5, 0) at x = 6.1: y = 1.5 + sqrt(0.08).
  expectHit(r.world.castRay(Vec3(6, 1.2, 5), Vec3(0, 0, -10)), r.capsule, r.shapeOf(r.capsule), 0.47,
            Vec3(6, 1.2, 0.3), Vec3::UnitZ());
  const Real cap_y = 1.5 + std::sqrt(0.08);
  expectHit(r.world.castRay(Vec3(6.1, 5, 0), down), r.capsule, r.shapeOf(r.capsule), (5 - cap_y) / 10,
            Vec3(6.1, cap_y, 0), Vec3(0.1, cap_y - 1.5, 0) / 0.3);
  // Cylinder: top cap at y = 1.3, side at z = 0.4.
  expectHit(r.world.castRay(Vec3(9.2, 5, 0), down), r.cylinder, r.shapeOf(r.cylinder), 0.37, Vec3(9.2, 1.3, 0),
            Vec3::UnitY());
  expectHit(r.world.castRay(Vec3(9, 1, 5), Vec3(0, 0, -10)), r.cylinder, r.shapeOf(r.cylinder), 0.46,
            Vec3(9, 1, 0.4), Vec3::UnitZ());
  // Hull cube of half-size 0.5: top face y = 1.5.
  expectHit(r.world.castRay(Vec3(12.2, 5, 0.1), down), r.hull, r.shapeOf(r.hull), 0.35, Vec3(12.2, 1.5, 0.1),
            Vec3::UnitY());
  // Mesh: the quad at y = 0.2; x = 0.5 >= z = -0.3 lies in triangle 1.
  const auto m = r.world.castRay(Vec3(15.5, 5, -0.3), down);
  expectHit(m, r.mesh, r.shapeOf(r.mesh), 0.48, Vec3(15.5, 0.2, -0.3), Vec3::UnitY());
  EXPECT_EQ(m->triangle, 1);
  // Plane: y = 0 half-way down, where nothing stands.
  expectHit(r.world.castRay(Vec3(20, 5, 0), down), r.ground, r.shapeOf(r.ground), 0.5, Vec3(20, 0, 0), Vec3::UnitY());
  // Short of everything: no hit.
  EXPECT_FALSE(r.world.castRay(Vec3(20, 5, 0), Vec3(0, -4, 0)).has_value());
}

TEST(WorldQueries, RayCastAllListsEveryShapeAlongTheRayNearestFirst) {
  const ShapeRow r;
  // Straight down through the sphere's center onto the ground: the sphere
  // at y = 1.5 (0.35), the ground at y = 0 (0.5).
  const std::vector<RayHit> hits = r.world.castRayAll(Vec3(0, 5, 0), Vec3(0, -10, 0));
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_EQ(hits[0].body, r.sphere);
  EXPECT_NEAR(hits[0].fraction, 0.35, kExact);
  EXPECT_EQ(hits[1].body, r.ground);
  EXPECT_NEAR(hits[1].fraction, 0.5, kExact);
  // A horizontal ray at y = 1 through every body in the row: the sphere,
  // box, capsule, cylinder and hull in order of x (the mesh is at y = 0.2).
  const std::vector<RayHit> row = r.world.castRayAll(Vec3(-2, 1, 0), Vec3(20, 0, 0));
  const BodyId want[] = {r.sphere, r.box, r.capsule, r.cylinder, r.hull};
  ASSERT_EQ(row.size(), 5u);
  // Entry x: sphere -0.5; box turned 30 degrees: its near corner line along x at z = 0 is at 3 - 0.5 / cos 30;
  // capsule 5.7; cylinder 8.6; hull 11.5.
  const Real entry[] = {-0.5, 3 - 0.5 / std::cos(kPi / 6), 5.7, 8.6, 11.5};
  for (size_t i = 0; i < row.size(); ++i) {
    EXPECT_EQ(row[i].body, want[i]) << i;
    EXPECT_NEAR(row[i].fraction, (entry[i] + 2) / 20, kExact) << i;
  }
}

TEST(WorldQueries, ShapeCastsOfSphereBoxAndCapsuleStopWhereTheyFirstTouch) {
  const ShapeRow r;
  const Vec3 down(0, -10, 0);
  // A 0.25 m sphere onto the 0.5 m sphere: touches when the centers are
  // 0.75 apart, at y = 1.75; the contact point is on the target, (0, 1.5, 0).
  const auto s = r.world.castShape(ShapeDesc::sphere(0.25), test::pose(Vec3(0, 5, 0)), down);
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->body, r.sphere);
  EXPECT_EQ(s->shape, r.shapeOf(r.sphere));
  EXPECT_NEAR(s->fraction, 0.325, kGjk);
  EXPECT_LT((s->normal - Vec3::UnitY()).norm(), 1e-9);
  EXPECT_LT((s->point - Vec3(0, 1.5, 0)).norm(), 1e-9);
  // A box of half-size 0.25 onto the box top at 1.25: its bottom face
  // arrives when its center is at 1.5.
  const auto b = r.world.castShape(ShapeDesc::box(Vec3(0.25, 0.25, 0.25)), test::pose(Vec3(3.1, 5, 0.2)), down);
  ASSERT_TRUE(b.has_value());
  EXPECT_EQ(b->body, r.box);
  EXPECT_NEAR(b->fraction, 0.35, kGjk);
  EXPECT_LT((b->normal - Vec3::UnitY()).norm(), 1e-9);
  // An upright capsule (radius 0.2, half-height 0.3) onto the hull's top at
  // 1.5: its lowest point is 0.5 below its center, so the center stops at 2.
  const auto c = r.world.castShape(ShapeDesc::capsule(0.2, 0.3), test::pose(Vec3(12.2, 5, 0.1)), down);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->body, r.hull);
  EXPECT_NEAR(c->fraction, 0.3, kGjk);
  // A capsule lying along x swept sideways into the cylinder's side: its
  // round side (radius 0.2) meets the cylinder (radius 0.4) when the axes
  // are 0.6 apart, from z = 3 to z = 0.6 over a 5 m sweep.
  const auto side = r.world.castShape(ShapeDesc::capsule(0.2, 0.3),
                                      test::pose(Vec3(9, 1, 3), test::rotation(kPi / 2, Vec3::UnitZ())), Vec3(0, 0, -5));
  ASSERT_TRUE(side.has_value());
  EXPECT_EQ(side->body, r.cylinder);
  EXPECT_NEAR(side->fraction, 2.4 / 5, kGjk);
  // Missing everything: a sphere swept along the row above it all.
  EXPECT_FALSE(r.world.castShape(ShapeDesc::sphere(0.2), test::pose(Vec3(-2, 3, 0)), Vec3(20, 0, 0)).has_value());
}

TEST(WorldQueries, OverlapFindsTheShapesAQueryShapeTouchesAndNoOthers) {
  const ShapeRow r;
  // Spheres 0.3 and 0.5 overlap while their centers are closer than 0.8.
  EXPECT_EQ(r.world.overlap(ShapeDesc::sphere(0.3), test::pose(Vec3(0, 1.79, 0))),
            std::vector<ShapeId>{r.shapeOf(r.sphere)});
  EXPECT_TRUE(r.world.overlap(ShapeDesc::sphere(0.3), test::pose(Vec3(0, 1.81, 0))).empty());
  // A box standing on the ground beside the sphere touches both (its top at
  // y = 0.6 reaches the sphere's bottom at y = 0.5 near x = 0).
  const std::vector<ShapeId> both = r.world.overlap(ShapeDesc::box(Vec3(0.2, 0.3, 0.2)), test::pose(Vec3(0, 0.29, 0)));
  ASSERT_EQ(both.size(), 2u);  // ascending shape slots: the ground's comes first
  EXPECT_EQ(both[0], r.shapeOf(r.ground));
  EXPECT_EQ(both[1], r.shapeOf(r.sphere));
  // Into the mesh quad (y = 0.2) from below, clear of the ground.
  EXPECT_EQ(r.world.overlap(ShapeDesc::sphere(0.1), test::pose(Vec3(15.3, 0.15, 0.4))),
            std::vector<ShapeId>{r.shapeOf(r.mesh)});
}

TEST(WorldQueries, FiltersSelectByBodyTypeGroupMaskIgnoredBodyAndCallback) {
  ShapeRow r;
  const Vec3 from(0, 5, 0), down(0, -10, 0);  // sphere (dynamic) first, then the ground (static)
  const auto first = [&](const QueryFilter& f) { return r.world.castRay(from, down, f)->body; };
  EXPECT_EQ(first({}), r.sphere);
  QueryFilter no_dynamic;
  no_dynamic.dynamic_bodies = false;
  EXPECT_EQ(first(no_dynamic), r.ground);
  QueryFilter no_static;
  no_static.static_bodies = false;
  EXPECT_EQ(r.world.castRayAll(from, down, no_static).size(), 1u);
  QueryFilter ignore;
  ignore.ignore = r.sphere;
  EXPECT_EQ(first(ignore), r.ground);
  QueryFilter accept;
  accept.accept = [&](BodyId b, ShapeId s) { return !(b == r.sphere) && s.isValid(); };
  EXPECT_EQ(first(accept), r.ground);
  // Group and mask, as between two bodies: the sphere in group 2 is hidden
  // from a query whose mask leaves out 2, and a sphere whose mask leaves out
  // 4 does not see a query of group 4.
  r.world.setCollisionFilter(r.sphere, 2, ~4u);
  QueryFilter mask;
  mask.mask = ~2u;
  EXPECT_EQ(first(mask), r.ground);
  QueryFilter group;
  group.group = 4;
  EXPECT_EQ(first(group), r.ground);
  group.group = 1;
  EXPECT_EQ(first(group), r.sphere);
}

TEST(WorldQueries, QueriesSeeBodiesWhereTheyAreAfterTeleportsAndSteps) {
  World world;
  const BodyId ball = world.createBody(test::sphereDef("ball", Vec3(0, 10, 0), 1, 0.5));
  // Teleported 50 m away: found there, not where it was.
  world.setTransform(ball, Vec3(50, 10, 0), Quat::Identity());
  EXPECT_FALSE(world.castRay(Vec3(0, 20, 0), Vec3(0, -20, 0)).has_value());
  const auto there = world.castRay(Vec3(50, 20, 0), Vec3(0, -20, 0));
  ASSERT_TRUE(there.has_value());
  EXPECT_NEAR(there->point.y(), 10.5, kExact);
  // Falling 2 s (120 steps): its top is wherever the step left it, 0.5
  // above its center, however far it fell since its proxy was made.
  for (int i = 0; i < 120; ++i) world.step(1.0 / 60);
  const Real top = world.centerOfMass(ball).y() + 0.5;
  ASSERT_LT(top, 0);  // fell more than 10 m
  const auto hit = world.castRay(Vec3(50, 20, 0), Vec3(0, -100, 0));
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.y(), top, kExact);
  // A body created after the last step is found at once.
  const BodyId late = world.createBody(test::boxDef("late", Vec3(-30, 0, 0)));
  const auto box = world.castRay(Vec3(-30, 5, 0), Vec3(0, -10, 0));
  ASSERT_TRUE(box.has_value());
  EXPECT_EQ(box->body, late);
}

TEST(WorldQueries, BadQueriesThrowInputErrorNamingTheField) {
  const ShapeRow r;
  const Real nan = std::nan("");
  EXPECT_THROW(r.world.castRay(Vec3(nan, 0, 0), Vec3(0, -1, 0)), InputError);
  EXPECT_THROW(r.world.castRayAll(Vec3(0, 0, 0), Vec3(0, kInf, 0)), InputError);
  try {
    r.world.castShape(ShapeDesc::plane(Vec3::UnitY(), 0), test::pose(Vec3::Zero()), Vec3(0, -1, 0));
    FAIL() << "a plane is not a query shape";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "shape");
  }
  try {
    r.world.overlap(ShapeDesc::sphere(-1), test::pose(Vec3::Zero()));
    FAIL() << "a negative radius";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "shape.radius");
  }
  // A zero translation casts nothing.
  EXPECT_FALSE(r.world.castRay(Vec3(0, 5, 0), Vec3::Zero()).has_value());
}

}  // namespace
}  // namespace cairn
