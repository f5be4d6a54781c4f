// Narrowphase: contact manifolds between two shapes.
//
// Conventions (docs/collision.md):
//   normal    unit, world, from shape A toward shape B (section 12.4.2):
//             moving B along +normal separates the pair.
//   depth     > 0 penetrating, < 0 separated by -depth (a speculative
//             contact); contacts are reported while depth >= -margin.
//   position  world, midway between the two surfaces along the normal:
//             A's surface point is position + normal * depth / 2 and B's is
//             position - normal * depth / 2.
//   feature_id  names the pair of features that made the point (e.g. the
//             reference face, the incident vertex or the clipped edge), the
//             same frame after frame while they stay in touch, so a contact
//             cache can carry impulses over by matching ids.
//
// Pairs handled: every combination of sphere, box, capsule, cylinder and
// convex hull, each against a plane and against a static triangle mesh.
// Plane-plane, plane-mesh and mesh-mesh produce nothing (static geometry).
#pragma once

#include "cairn/shape.hpp"
#include "cairn/math.hpp"

#include <cstdint>
#include <vector>

namespace cairn {

struct ContactPoint {
  Vec3 position = Vec3::Zero();
  Real depth = 0;
  std::uint32_t feature_id = 0;
};

struct Manifold {
  static constexpr int kMaxPoints = 4;
  Vec3 normal = Vec3::UnitY();
  int count = 0;
  ContactPoint points[kMaxPoints];
  // Mesh pairs make one manifold per touching triangle: the triangle's index
  // in TriangleMeshData::triangles, else -1.
  int triangle = -1;
};

// Appends the manifolds of shapes a and b at world transforms ta, tb (each
// already including the shape's local offset) whose surfaces are closer than
// `margin`. Most pairs give at most one manifold; a mesh gives one per
// triangle. Returns the number appended. Never produces NaN: coincident
// shapes get a fixed, finite normal.
int collide(const ShapeDesc& a, const Transform& ta, const ShapeDesc& b, const Transform& tb, Real margin,
            std::vector<Manifold>& out);

// False for pairs collide() never reports (plane-plane, plane-mesh, mesh-mesh).
bool canCollide(ShapeType a, ShapeType b);

}  // namespace cairn
