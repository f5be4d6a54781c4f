/// @file
/// Handles: small integers into the World's arrays, never pointers (Box2D's
/// b2BodyId, Jolt's BodyID). Each carries the generation of its slot: when
/// an object is destroyed its slot's generation advances, so a handle kept
/// past the destruction is recognised as stale and refused with a
/// HandleError instead of reaching whatever reuses the slot.
#pragma once

#include <cstdint>

namespace cairn {
/// A body of a World.
struct BodyId {
  std::int32_t index = -1;  ///< -1: the world (the static frame every joint may attach to)
  std::uint32_t generation = 0;  ///< the slot's generation when the handle was made
  bool isWorld() const { return index < 0; }  ///< true for kWorldBody
  friend bool operator==(BodyId a, BodyId b) { return a.index == b.index && a.generation == b.generation; }  ///< same slot and generation
};
inline constexpr BodyId kWorldBody{};  ///< the static world frame
/// A joint of a World.
struct JointId {
  std::int32_t index = -1;  ///< -1: no joint
  std::uint32_t generation = 0;  ///< the slot's generation when the handle was made
  bool isValid() const { return index >= 0; }  ///< false for a default-made handle (it names nothing)
  friend bool operator==(JointId a, JointId b) { return a.index == b.index && a.generation == b.generation; }  ///< same slot and generation
};
/// A spring of a World.
struct SpringId {
  std::int32_t index = -1;  ///< slot index; -1: none
  std::uint32_t generation = 0;  ///< the slot's generation when the handle was made
  bool isValid() const { return index >= 0; }  ///< false for a default-made handle (it names nothing)
  friend bool operator==(SpringId a, SpringId b) { return a.index == b.index && a.generation == b.generation; }  ///< same slot and generation
};

/// A shape of a body: the world's shape slot.
struct ShapeId {
  std::int32_t index = -1;  ///< slot index; -1: none
  std::uint32_t generation = 0;  ///< the slot's generation when the handle was made
  bool isValid() const { return index >= 0; }  ///< false for a default-made handle (it names nothing)
  friend bool operator==(ShapeId a, ShapeId b) { return a.index == b.index && a.generation == b.generation; }  ///< same slot and generation
};

}  // namespace cairn
