// Shared helpers for the collision tests: shapes, poses, exact signed
// distances and support functions used as brute-force references.
#pragma once

#include "collision/hull.hpp"
#include "collision/manifold.hpp"
#include "collision/mesh_bvh.hpp"
#include "collision/support.hpp"

#include <memory>
#include <random>

namespace cairn::test {

inline Transform pose(const Vec3& p, const Quat& q = Quat::Identity()) { return Transform{p, q}; }
inline Quat rotation(Real angle, const Vec3& axis) { return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized())); }

inline ShapeDesc hullShape(const std::vector<Vec3>& pts) {
  ShapeDesc s;
  s.type = ShapeType::ConvexHull;
  s.hull = buildConvexHull(pts);
  return s;
}

inline ShapeDesc cubeHull(Real h) {
  std::vector<Vec3> p;
  for (int i = 0; i < 8; ++i) p.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  return hullShape(p);
}

// An irregular hull: a squashed icosahedron-like blob with 20 points.
inline ShapeDesc blobHull() {
  std::mt19937 rng(123);
  std::normal_distribution<Real> g(0, 1);
  std::vector<Vec3> p;
  for (int i = 0; i < 20; ++i) p.push_back(Vec3(g(rng), g(rng), g(rng)).normalized().cwiseProduct(Vec3(0.6, 0.45, 0.5)));
  return hullShape(p);
}

inline ShapeDesc meshShape(std::shared_ptr<const TriangleMeshData> mesh) {
  ShapeDesc s;
  s.type = ShapeType::Mesh;
  s.mesh = std::move(mesh);
  return s;
}

// A bumpy n x n grid of quads (2 n^2 triangles) over [-half, half]^2, heights
// amplitude * sin(1.3 x) cos(0.9 z) so that neighbouring triangles differ,
// counter-clockwise seen from above (+y).
inline std::shared_ptr<TriangleMeshData> bumpyTerrain(int n, Real half, Real amplitude, bool with_bvh) {
  auto mesh = std::make_shared<TriangleMeshData>();
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const Real x = -half + 2 * half * i / n, z = -half + 2 * half * j / n;
      mesh->vertices.emplace_back(x, amplitude * std::sin(1.3 * x) * std::cos(0.9 * z), z);
    }
  auto id = [&](int i, int j) { return i * (n + 1) + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      mesh->triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      mesh->triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  if (with_bvh) buildMeshBvh(*mesh);
  return mesh;
}

// A 2 x 2 square in the plane y = 0.2 split along the diagonal x = z:
// triangle 0 where z >= x, triangle 1 where x >= z, both counter-clockwise
// seen from +y.
inline ShapeDesc quadMesh() {
  auto m = std::make_shared<TriangleMeshData>();
  m->vertices = {Vec3(-1, 0.2, -1), Vec3(-1, 0.2, 1), Vec3(1, 0.2, 1), Vec3(1, 0.2, -1)};
  m->triangles = {{0, 1, 2}, {0, 2, 3}};
  buildMeshBvh(*m);
  return meshShape(m);
}

// Exact signed distance from world point x to the surface of s at t
// (negative inside). For hulls the largest face-plane distance: exact
// inside and on the surface, a lower bound outside.
inline Real signedDistance(const ShapeDesc& s, const Transform& t, const Vec3& x) {
  const Vec3 l = t.applyInverse(x);
  switch (s.type) {
    case ShapeType::Sphere: return l.norm() - s.radius;
    case ShapeType::Box: {
      const Vec3 q = l.cwiseAbs() - s.half_extents;
      return q.cwiseMax(0).norm() + std::min(q.maxCoeff(), Real(0));
    }
    case ShapeType::Capsule: {
      const Real y = std::clamp(l.y(), -s.half_height, s.half_height);
      return (l - Vec3(0, y, 0)).norm() - s.radius;
    }
    case ShapeType::Cylinder: {
      const Real dr = std::hypot(l.x(), l.z()) - s.radius, dy = std::abs(l.y()) - s.half_height;
      return std::min(std::max(dr, dy), Real(0)) + std::hypot(std::max(dr, Real(0)), std::max(dy, Real(0)));
    }
    case ShapeType::ConvexHull: {
      Real m = -kInf;
      for (size_t f = 0; f < s.hull->faces.size(); ++f) m = std::max(m, s.hull->face_normals[f].dot(l) - s.hull->face_offsets[f]);
      return m;
    }
    case ShapeType::Plane: {
      Vec3 n;
      Real d;
      worldPlane(s, t, n, d);
      return n.dot(x) - d;
    }
    case ShapeType::Mesh: break;
  }
  return kInf;
}

// f(u) = h_A(u) + h_B(-u): the overlap of the shapes' projections on u. Its
// minimum over unit u is the penetration depth (negative: minus the
// distance), and the minimizer is the normal from A toward B.
inline Real overlapAlong(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, const Vec3& u) {
  return u.dot(supportWorld(a, ta, u)) - u.dot(supportWorld(b, tb, -u));
}

// Local random search for a minimum of f near direction u (f has kinks
// where the supporting features change, so no derivatives): the step shrinks
// from 0.1 rad to 1e-10 rad, and is kept while it keeps finding lower values.
inline Real refineDepth(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Vec3& u,
                        std::mt19937& rng) {
  std::normal_distribution<Real> g(0, 1);
  Real f = overlapAlong(a, ta, b, tb, u);
  for (Real step = 0.1; step > 1e-10; step *= 0.7) {
    for (int k = 0; k < 16; ++k) {
      const Vec3 v = (u + step * Vec3(g(rng), g(rng), g(rng))).normalized();
      const Real fv = overlapAlong(a, ta, b, tb, v);
      if (fv < f) f = fv, u = v, step /= 0.7;
    }
  }
  return f;
}

// Brute-force minimum of f over the sphere of directions: 4000 Fibonacci
// directions, then the local search from the best 4 of them and from any
// extra seed directions given. Accurate to ~1e-9 at smooth or cone-shaped
// minima; along a ridge (a capsule's or cylinder's rim) random steps rarely
// stay on it and the search can stop ~1e-5 short, which a seed at the true
// minimizer fixes.
inline Real bruteForceDepth(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb,
                            Vec3* best_dir = nullptr, const std::vector<Vec3>& seeds = {}) {
  const int n = 4000;
  std::vector<std::pair<Real, Vec3>> samples;
  const Real golden = kPi * (3 - std::sqrt(Real(5)));
  for (int i = 0; i < n; ++i) {
    const Real y = 1 - 2 * (i + Real(0.5)) / n, r = std::sqrt(1 - y * y);
    const Vec3 u(r * std::cos(golden * i), y, r * std::sin(golden * i));
    samples.emplace_back(overlapAlong(a, ta, b, tb, u), u);
  }
  std::partial_sort(samples.begin(), samples.begin() + 4, samples.end(),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
  samples.resize(4);
  for (const Vec3& s : seeds) samples.emplace_back(overlapAlong(a, ta, b, tb, s), s);
  std::mt19937 rng(99);
  Real best = kInf;
  Vec3 bu = Vec3::UnitY();
  for (auto& [f0, u0] : samples) {
    Vec3 u = u0;
    const Real f = refineDepth(a, ta, b, tb, u, rng);
    if (f < best) best = f, bu = u;
  }
  if (best_dir) *best_dir = bu;
  return best;
}

inline Real maxDepth(const Manifold& m) {
  Real d = -kInf;
  for (int i = 0; i < m.count; ++i) d = std::max(d, m.points[i].depth);
  return d;
}

}  // namespace cairn::test
