// Triangle meshes: the BVH and the per-triangle manifolds it feeds.
#include "collision/mesh_bvh.hpp"
#include "collision_test_shapes.hpp"

#include <gtest/gtest.h>

#include <set>

namespace cairn {
namespace {

// The bumpy 40 x 40 terrain (3200 triangles) over [-4, 4]^2.
std::shared_ptr<TriangleMeshData> terrain(bool with_bvh) { return test::bumpyTerrain(40, 4, 0.2, with_bvh); }

TEST(CollisionMeshBvh, CoversEveryTriangleOnceAndBoundsItsLeaves) {
  const auto mesh = terrain(true);
  ASSERT_FALSE(mesh->bvh.empty());
  std::multiset<int> seen(mesh->bvh_order.begin(), mesh->bvh_order.end());
  ASSERT_EQ(seen.size(), mesh->triangles.size());
  for (int t = 0; t < static_cast<int>(mesh->triangles.size()); ++t) EXPECT_EQ(seen.count(t), 1u);
  for (const auto& node : mesh->bvh) {
    const Aabb box{node.lo, node.hi};
    if (node.count > 0) {
      EXPECT_LE(node.count, 4);
      for (int k = node.first; k < node.first + node.count; ++k) {
        const auto& tri = mesh->triangles[mesh->bvh_order[k]];
        EXPECT_TRUE(box.contains(triangleAabb(mesh->vertices[tri[0]], mesh->vertices[tri[1]], mesh->vertices[tri[2]])));
      }
    } else {
      EXPECT_TRUE(box.contains(Aabb{mesh->bvh[node.first].lo, mesh->bvh[node.first].hi}));
      EXPECT_TRUE(box.contains(Aabb{mesh->bvh[node.first + 1].lo, mesh->bvh[node.first + 1].hi}));
    }
  }
}

// The tree only prunes: manifolds through it must equal the full scan's,
// bit for bit, for shapes dropped anywhere on the terrain.
TEST(CollisionMeshBvh, ManifoldsMatchTheFullScan) {
  ShapeDesc with, without;
  with.type = without.type = ShapeType::Mesh;
  with.mesh = terrain(true);
  without.mesh = terrain(false);
  const std::vector<ShapeDesc> shapes = {ShapeDesc::sphere(0.4), ShapeDesc::box(Vec3(0.5, 0.3, 0.4)), ShapeDesc::capsule(0.2, 0.5),
                                         ShapeDesc::cylinder(0.3, 0.3), test::blobHull()};
  std::mt19937 rng(5);
  std::uniform_real_distribution<Real> u(-3.5, 3.5), h(-0.2, 0.5);
  std::normal_distribution<Real> g(0, 1);
  int touching = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const ShapeDesc& s = shapes[trial % shapes.size()];
    const Transform ts = test::pose(Vec3(u(rng), h(rng), u(rng)), Quat(g(rng), g(rng), g(rng), g(rng)).normalized());
    const Transform tm = test::pose(Vec3(0, -0.1, 0), test::rotation(0.1, Vec3::UnitY()));
    std::vector<Manifold> a, b;
    collide(with, tm, s, ts, 0.05, a);
    collide(without, tm, s, ts, 0.05, b);
    ASSERT_EQ(a.size(), b.size()) << "trial " << trial;
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].triangle, b[k].triangle);
      EXPECT_EQ(a[k].normal, b[k].normal);
      ASSERT_EQ(a[k].count, b[k].count);
      for (int i = 0; i < a[k].count; ++i) {
        EXPECT_EQ(a[k].points[i].depth, b[k].points[i].depth);
        EXPECT_EQ(a[k].points[i].feature_id, b[k].points[i].feature_id);
      }
      if (k > 0) {
        EXPECT_LT(a[k - 1].triangle, a[k].triangle);  // in triangle order
      }
    }
    touching += !a.empty();
  }
  EXPECT_GT(touching, 30);  // the test really exercised contacts
}

}  // namespace
}  // namespace cairn
