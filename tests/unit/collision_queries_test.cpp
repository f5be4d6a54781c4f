// The broadphase front end of the queries: its answers must equal testing
// every shape one by one (the tree only prunes, never decides), whatever
// order the proxies were inserted in.
//
// The per-shape casts are the same functions on both sides, so the
// comparisons are exact (==): fractions, users and the order of lists.
#include "cairn/error.hpp"
#include "collision/mesh_bvh.hpp"
#include "collision/overlap.hpp"
#include "collision/queries.hpp"
#include "collision/shape_cast.hpp"
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace cairn {
namespace {

using test::pose;
using test::rotation;

// A mixed scene: a ground plane, a 4 x 4 x 4 block of rotated boxes,
// spheres, capsules, cylinders, hulls and a bumpy mesh off to the side.
struct Scene {
  std::vector<ShapeDesc> shapes;
  std::vector<Transform> poses;

  ProxyLookup lookup() const {
    return [this](int user) { return QueryShape{&shapes[static_cast<size_t>(user)], poses[static_cast<size_t>(user)]}; };
  }
  // Proxies as the World makes them: tight boxes grown by a margin.
  BroadPhase broadphase(bool reversed) const {
    BroadPhase bp;
    const int n = static_cast<int>(shapes.size());
    for (int k = 0; k < n; ++k) {
      const int i = reversed ? n - 1 - k : k;
      Aabb box = shapeAabb(shapes[static_cast<size_t>(i)], poses[static_cast<size_t>(i)]);
      if (!box.isInfinite()) box = box.expanded(0.05);
      bp.createProxy(box, i);
    }
    return bp;
  }
};

Scene mixedScene() {
  Scene s;
  auto add = [&](const ShapeDesc& d, const Transform& t) {
    s.shapes.push_back(d);
    s.poses.push_back(t);
  };
  add(ShapeDesc::plane(Vec3::UnitY(), 0), pose(Vec3::Zero()));
  std::mt19937 rng(21);
  std::uniform_real_distribution<Real> u(-1, 1);
  const ShapeDesc kinds[] = {ShapeDesc::box(Vec3(0.4, 0.3, 0.35)), ShapeDesc::sphere(0.4), ShapeDesc::capsule(0.2, 0.3),
                             ShapeDesc::cylinder(0.35, 0.3), test::blobHull()};
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 4; ++y)
      for (int z = 0; z < 4; ++z) {
        const Vec3 p(1.2 * x - 1.8 + 0.1 * u(rng), 0.5 + 1.1 * y, 1.2 * z - 1.8 + 0.1 * u(rng));
        add(kinds[(x + 2 * y + 3 * z) % 5], pose(p, rotation(2 * u(rng), Vec3(u(rng), u(rng), u(rng)))));
      }
  add(test::meshShape(test::bumpyTerrain(12, 2, 0.2, true)), pose(Vec3(5, 0.3, 0)));
  return s;
}

struct Ray {
  Vec3 origin, translation;
};

std::vector<Ray> randomRays(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::vector<Ray> rays;
  for (int i = 0; i < count; ++i) {
    const Vec3 from(5 * u(rng), 6 + 2 * u(rng), 5 * u(rng)), to(3.5 * u(rng) + (i % 4 == 0 ? 5 : 0), 2.5 + 2.5 * u(rng), 3.5 * u(rng));
    rays.push_back({from, (i % 3 == 0 ? 0.5 : 1.3) * (to - from)});
  }
  return rays;
}

bool sameHit(const ProxyHit& a, const ProxyHit& b) {
  return a.user == b.user && a.hit.fraction == b.hit.fraction && a.hit.normal == b.hit.normal &&
         a.hit.point == b.hit.point && a.hit.triangle == b.hit.triangle && a.hit.inside == b.hit.inside;
}

// Every shape tested one by one, sorted by fraction then user.
template <class Cast>
std::vector<ProxyHit> bruteForce(const Scene& s, const ProxyFilter& filter, Cast&& cast) {
  std::vector<ProxyHit> all;
  for (int i = 0; i < static_cast<int>(s.shapes.size()); ++i) {
    if (filter && !filter(i)) continue;
    if (const auto h = cast(s.shapes[static_cast<size_t>(i)], s.poses[static_cast<size_t>(i)])) all.push_back({i, *h});
  }
  std::sort(all.begin(), all.end(), [](const ProxyHit& a, const ProxyHit& b) {
    return a.hit.fraction != b.hit.fraction ? a.hit.fraction < b.hit.fraction : a.user < b.user;
  });
  return all;
}

void expectSameClosest(const std::optional<ProxyHit>& got, const std::vector<ProxyHit>& want) {
  ASSERT_EQ(got.has_value(), !want.empty());
  if (got) {
    EXPECT_TRUE(sameHit(*got, want[0]));
  }
}

void expectSameList(const std::vector<ProxyHit>& got, const std::vector<ProxyHit>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t k = 0; k < got.size(); ++k)
    EXPECT_TRUE(sameHit(got[k], want[k])) << k << ": user " << got[k].user << " vs " << want[k].user << ", fraction "
                                          << got[k].hit.fraction << " vs " << want[k].hit.fraction << ", triangle "
                                          << got[k].hit.triangle << " vs " << want[k].hit.triangle << ", normal "
                                          << got[k].hit.normal.transpose() << " vs " << want[k].hit.normal.transpose();
}

TEST(QueryRayCast, ClosestAndAllEqualTestingEveryShapeInAnyInsertionOrder) {
  const Scene s = mixedScene();
  const BroadPhase forward = s.broadphase(false), backward = s.broadphase(true);
  int hits = 0, multi = 0;
  for (const Ray& r : randomRays(400, 1)) {
    const auto want = bruteForce(s, {}, [&](const ShapeDesc& d, const Transform& t) {
      return rayCast(d, t, r.origin, r.translation);
    });
    for (const BroadPhase* bp : {&forward, &backward}) {
      expectSameClosest(rayCastClosest(*bp, r.origin, r.translation, s.lookup()), want);
      expectSameList(rayCastAll(*bp, r.origin, r.translation, s.lookup()), want);
    }
    hits += !want.empty();
    multi += want.size() > 1;
  }
  EXPECT_GT(hits, 120);
  EXPECT_GT(multi, 50);
}

TEST(QueryRayCast, FilterLeavesOutTheRejectedShapesOnly) {
  const Scene s = mixedScene();
  const BroadPhase bp = s.broadphase(false);
  const ProxyFilter odd = [](int user) { return user % 2 == 1; };  // no ground plane
  for (const Ray& r : randomRays(200, 2)) {
    const auto want = bruteForce(s, odd, [&](const ShapeDesc& d, const Transform& t) {
      return rayCast(d, t, r.origin, r.translation);
    });
    expectSameClosest(rayCastClosest(bp, r.origin, r.translation, s.lookup(), odd), want);
    expectSameList(rayCastAll(bp, r.origin, r.translation, s.lookup(), odd), want);
  }
}

TEST(QueryShapeCast, ClosestAndAllEqualCastingAgainstEveryShape) {
  const Scene s = mixedScene();
  const BroadPhase forward = s.broadphase(false), backward = s.broadphase(true);
  const ShapeDesc movers[] = {ShapeDesc::sphere(0.3), ShapeDesc::box(Vec3(0.3, 0.2, 0.25)), ShapeDesc::capsule(0.15, 0.3)};
  std::mt19937 rng(3);
  std::uniform_real_distribution<Real> u(-1, 1);
  int k = 0, hits = 0;
  for (const Ray& r : randomRays(90, 3)) {
    const ShapeDesc& m = movers[k++ % 3];
    // Normalized as the front end normalizes it, so both sides see the same bits.
    const Transform at = pose(r.origin, rotation(3 * u(rng), Vec3(u(rng), u(rng), u(rng))).normalized());
    const auto want = bruteForce(s, {}, [&](const ShapeDesc& d, const Transform& t) {
      return shapeCast(m, at, r.translation, d, t);
    });
    for (const BroadPhase* bp : {&forward, &backward}) {
      expectSameClosest(shapeCastClosest(*bp, m, at, r.translation, s.lookup()), want);
      expectSameList(shapeCastAll(*bp, m, at, r.translation, s.lookup()), want);
    }
    hits += !want.empty();
  }
  EXPECT_GT(hits, 40);
}

TEST(QueryOverlap, ListsEveryOverlappingShapeAscending) {
  const Scene s = mixedScene();
  const BroadPhase bp = s.broadphase(true);
  const ShapeDesc queries[] = {ShapeDesc::sphere(0.6), ShapeDesc::box(Vec3(0.5, 0.4, 0.7)), ShapeDesc::capsule(0.3, 0.8),
                               test::cubeHull(0.5)};
  std::mt19937 rng(4);
  std::uniform_real_distribution<Real> u(-1, 1);
  int found = 0;
  for (int i = 0; i < 200; ++i) {
    const ShapeDesc& q = queries[i % 4];
    const Transform at = pose(Vec3(3 * u(rng) + (i % 5 == 0 ? 5 : 0), 2.5 + 2.5 * u(rng), 3 * u(rng)),
                              rotation(3 * u(rng), Vec3(u(rng), u(rng), u(rng))).normalized());
    std::vector<int> want;
    for (int k = 0; k < static_cast<int>(s.shapes.size()); ++k)
      if (overlaps(q, at, s.shapes[static_cast<size_t>(k)], s.poses[static_cast<size_t>(k)])) want.push_back(k);
    EXPECT_EQ(overlapAll(bp, q, at, s.lookup()), want);
    found += static_cast<int>(want.size());
  }
  EXPECT_GT(found, 200);
}

TEST(QueryRayCast, TreeWalkVisitsExactlyTheLeavesTheSegmentMeets) {
  // With no clipping (visit returns the same max), the walk must reach every
  // leaf whose box the segment touches and no other: the reference is the
  // slab test on each leaf's box.
  const Scene s = mixedScene();
  const BroadPhase bp = s.broadphase(false);
  const DynamicTree& tree = bp.tree();
  const Vec3 extent(0.1, 0.2, 0.05);
  for (const Ray& r : randomRays(200, 5)) {
    std::vector<int> visited, want;
    tree.rayCast(r.origin, r.translation, 1, extent, [&](int leaf, Real max_f) {
      visited.push_back(tree.user(leaf));
      return max_f;
    });
    for (int h = 0; h < static_cast<int>(s.shapes.size()); ++h) {
      if (bp.isInfinite(h)) continue;
      Real t0 = 0, t1 = 1;
      const Aabb& b = bp.fatAabb(h);
      if (clipLineToBox(b.lo - extent, b.hi + extent, r.origin, r.translation.cwiseInverse(), t0, t1)) want.push_back(h);
    }
    std::sort(visited.begin(), visited.end());
    EXPECT_EQ(visited, want);
  }
}

TEST(QueryInput, BadInputNamesTheQueryAndTheField) {
  const Scene s = mixedScene();
  const BroadPhase bp = s.broadphase(false);
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  try {
    rayCastClosest(bp, Vec3(0, nan, 0), Vec3(0, -1, 0), s.lookup());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "ray cast");
    EXPECT_EQ(e.field(), "origin");
  }
  try {
    rayCastAll(bp, Vec3::Zero(), Vec3(kInf, 0, 0), s.lookup());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "translation");
  }
  try {
    shapeCastClosest(bp, s.shapes.back(), pose(Vec3::Zero()), Vec3(1, 0, 0), s.lookup());  // a mesh
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "shape cast");
    EXPECT_EQ(e.field(), "shape");
  }
  try {
    overlapAll(bp, ShapeDesc::sphere(1), Transform{Vec3::Zero(), Quat(0, 0, 0, 0)}, s.lookup());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.object(), "overlap query");
    EXPECT_EQ(e.field(), "pose.orientation");
  }
  // A zero translation casts nothing; an empty broadphase holds nothing.
  EXPECT_TRUE(rayCastAll(bp, Vec3(0, 5, 0), Vec3::Zero(), s.lookup()).empty());
  EXPECT_FALSE(rayCastClosest(BroadPhase(), Vec3(0, 5, 0), Vec3(0, -10, 0), s.lookup()));
}

}  // namespace
}  // namespace cairn
