// Median-split BVH over mesh triangles (see mesh_bvh.hpp).
#include "collision/mesh_bvh.hpp"

#include <algorithm>

namespace cairn {
namespace {

constexpr int kLeafSize = 4;

struct Builder {
  TriangleMeshData& mesh;
  std::vector<Aabb> boxes;
  std::vector<Vec3> centers;

  // Builds the subtree over bvh_order[first, first + count) into node `at`.
  void build(int at, int first, int count) {
    Aabb bounds, spread;
    for (int k = first; k < first + count; ++k) {
      bounds = bounds.merged(boxes[mesh.bvh_order[k]]);
      spread.grow(centers[mesh.bvh_order[k]]);
    }
    mesh.bvh[at].lo = bounds.lo;
    mesh.bvh[at].hi = bounds.hi;
    if (count <= kLeafSize) {
      mesh.bvh[at].first = first;
      mesh.bvh[at].count = count;
      return;
    }
    int axis = 0;
    spread.extent().maxCoeff(&axis);
    const int half = count / 2;
    auto begin = mesh.bvh_order.begin() + first;
    // Ties broken by index so the tree does not depend on the sort's whims.
    std::nth_element(begin, begin + half, begin + count, [&](int a, int b) {
      return centers[a][axis] != centers[b][axis] ? centers[a][axis] < centers[b][axis] : a < b;
    });
    const int left = static_cast<int>(mesh.bvh.size());
    mesh.bvh.emplace_back();
    mesh.bvh.emplace_back();
    mesh.bvh[at].first = left;
    mesh.bvh[at].count = 0;
    build(left, first, half);
    build(left + 1, first + half, count - half);
  }
};

}  // namespace

void buildMeshBvh(TriangleMeshData& mesh) {
  mesh.bvh.clear();
  mesh.bvh_order.clear();
  const int n = static_cast<int>(mesh.triangles.size());
  if (n == 0) return;
  Builder b{mesh, {}, {}};
  b.boxes.reserve(n);
  b.centers.reserve(n);
  for (const auto& t : mesh.triangles) {
    b.boxes.push_back(triangleAabb(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]));
    b.centers.push_back(b.boxes.back().center());
  }
  mesh.bvh_order.resize(n);
  for (int i = 0; i < n; ++i) mesh.bvh_order[i] = i;
  mesh.bvh.reserve(2 * (n / kLeafSize + 1));
  mesh.bvh.emplace_back();
  b.build(0, 0, n);
}

}  // namespace cairn
