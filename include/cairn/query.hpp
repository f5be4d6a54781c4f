/// @file
/// What the World's geometric queries return (World::castRay, castRayAll,
/// castShape, overlap), and how a query picks the shapes it sees.
///
/// Conventions: a cast covers the segment origin + t * translation for t in
/// [0, 1]; `fraction` is that t at the first contact. Normals are unit, world
/// frame, pointing out of the shape hit (against the cast). A ray that starts
/// inside a solid shape hits it at fraction 0 with the normal opposite to the
/// ray (docs/collision.md, "Queries").
#pragma once

#include "cairn/handles.hpp"
#include "cairn/math.hpp"

#include <cstdint>
#include <functional>
#include <optional>

namespace cairn {
/// A ray cast hit (World::castRay).
struct RayHit {
  BodyId body;    ///< the body hit
  ShapeId shape;  ///< the shape hit, one of that body's
  Real fraction = 1;        ///< along the translation, in [0, 1]
  Vec3 point = Vec3::Zero();   ///< world
  Vec3 normal = Vec3::Zero();  ///< world, unit, out of the shape hit
  std::int32_t triangle = -1;  ///< triangle meshes: the triangle hit
};
/// A shape cast hit (World::castShape).
struct ShapeCastHit {
  BodyId body;    ///< the body hit
  ShapeId shape;  ///< the shape hit, one of that body's
  Real fraction = 1;           ///< time of impact along the translation, in [0, 1]
  Vec3 point = Vec3::Zero();   ///< world contact point at the time of impact
  Vec3 normal = Vec3::Zero();  ///< world, unit, out of the shape hit
  std::int32_t triangle = -1;  ///< triangle meshes: the triangle hit; -1 otherwise
};

/// Which shapes a query sees: those whose body's collision group meets
/// `mask` (and whose mask meets `group`), of the body types asked for, not
/// `ignore`, and accepted by `accept` if given.
struct QueryFilter {
  std::uint32_t group = 0xffffffffu;  ///< the query's group: a body's collision_mask must meet it
  std::uint32_t mask = 0xffffffffu;   ///< groups the query sees: a body's collision_group must meet it
  bool static_bodies = true;     ///< see shapes of static bodies
  bool kinematic_bodies = true;  ///< see shapes of kinematic bodies
  bool dynamic_bodies = true;    ///< see shapes of dynamic bodies
  BodyId ignore = BodyId{};  ///< kWorldBody: ignore nothing
  std::function<bool(BodyId, ShapeId)> accept;  ///< optional: false rejects that shape; empty accepts all
};

}  // namespace cairn
