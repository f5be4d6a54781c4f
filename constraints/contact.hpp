// Contact constraints: a persistent manifold between two shapes and the rows
// it writes each (sub)step.
//
// For a point with anchors p_a on A's surface and p_b on B's, normal n from
// A to B and separation s = (p_b - p_a).n (negative when penetrating):
//
//   normal row    J = [-n, -(r_a x n), n, r_b x n],  lambda >= 0
//                 rhs = -s/h while separated (speculative: close the gap,
//                 no more); Newton's restitution -e v_n0 when the approach
//                 speed v_n0 (at detection) exceeds the threshold; the
//                 penetration beyond the slop is pushed out at
//                 contact_erp/h per step (split impulse or Baumgarte).
//   friction rows along t1 (the sliding direction when sliding) and
//                 t2 = n x t1, |lambda_t| <= mu lambda_n (pyramid; the
//                 bounds follow the normal row during the solve)
//   rolling rows  optional: torsional about n and rolling about t1, t2,
//                 |lambda| <= coefficient * lambda_n of the deepest point
//                 times the point count (one set per manifold)
#pragma once

#include "constraints/parts.hpp"
#include "cairn/defs.hpp"

#include <cstddef>
#include <cstdint>

namespace cairn {

struct ContactPointState {
  std::uint32_t feature_id = 0;
  Vec3 local_a = Vec3::Zero();   // anchor on A's surface, A's frame (from its center of mass)
  Vec3 local_b = Vec3::Zero();   // anchor on B's surface, B's frame
  Real depth = 0;                // at detection (> 0 penetrating)
  Real approach_speed = 0;       // relative normal velocity at detection (< 0 approaching)
  Real normal_impulse = 0;       // accumulated, carried for warm starting
  Real max_impulse = 0;          // the largest normal impulse of this step's substeps (restitution acts only where > 0)
  Vec3 friction_impulse = Vec3::Zero();  // accumulated tangential impulse, world vector
  std::int32_t normal_row = -1;  // this (sub)step's row index
  std::int32_t friction_row = -1;  // first of one or two (SolverSettings::friction_directions)
};

// The first 64 bytes hold what the step's walks over every contact read:
// the shapes and bodies, the point count, the flags, the depth after the
// step and the rolling and torsional coefficients (which say whether the
// contact is a row group: the graph's layout and the islands' row counts
// read them for every contact). Contacts are 704 bytes (11 cache lines)
// apart, each starting a line: a walk that reads only these fields touches
// one line of each.
struct alignas(64) Contact {
  std::int32_t shape_a = -1, shape_b = -1;  // world shape indices, shape_a < shape_b
  std::int32_t triangle = -1;               // mesh triangle, else -1
  BodyId body_a, body_b;
  int count = 0;
  bool enabled = true;                      // a callback may veto
  bool touching = false;                    // some point within the margin this step
  bool began = false;                       // first step touching (for events)
  Real depth_after = 0;                     // deepest overlap after the last step (the penetration watcher)
  Real rolling_friction = 0, torsional_friction = 0;
  Vec3 normal = Vec3::UnitY();              // from A to B, world
  ContactPointState points[4];
  Real friction = 0, restitution = 0;
  Vec3 rolling_impulse = Vec3::Zero();      // world vector, carried
  std::int32_t rolling_row = -1;
  // Where the narrowphase made this manifold, in A's frame (for recycling,
  // world/world_contacts.cpp): B's offset R_a^T (x_b - x_a), B's rotation
  // q_a^-1 q_b, and the normal R_a^T n.
  Vec3 made_offset = Vec3::Zero();
  Quat made_rotation = Quat::Identity();
  Vec3 made_normal = Vec3::UnitY();

  std::uint64_t key() const { return keyOf(shape_a, shape_b, triangle); }
  static std::uint64_t keyOf(std::int32_t shape_a, std::int32_t shape_b, std::int32_t triangle) {
    return (std::uint64_t(std::uint32_t(shape_a)) << 40) ^ (std::uint64_t(std::uint32_t(shape_b)) << 16) ^
           std::uint64_t(std::uint32_t(triangle + 1) & 0xffff);
  }
  Real totalNormalImpulse() const {
    Real s = 0;
    for (int i = 0; i < count; ++i) s += points[i].normal_impulse;
    return s;
  }
};
static_assert(offsetof(Contact, torsional_friction) + sizeof(Real) <= 64, "the walks' fields leave the first line");

// Asks the cache for a contact's lines ahead of a walk that visits the
// contacts in another order than they are stored (the solver's lane
// order): a large scene's contacts leave the cache, and each visit would
// otherwise wait for its lines one after another.
inline void prefetchContact(const Contact& c) {
  const char* p = reinterpret_cast<const char*>(&c);
  for (size_t k = 0; k < sizeof(Contact); k += 64) __builtin_prefetch(p + k);
}

struct ContactRowSettings {
  Real h = Real(1) / 60;
  Real contact_erp = Real(0.2);
  Real cfm = 0;  // global CFM (ODE units)
  Real slop = Real(0.005);
  Real restitution_threshold = Real(0.2);
  Real max_correction_velocity = Real(10);
  Correction correction = Correction::PseudoVelocity;
  bool warm_start = true;
  Real warm_start_factor = 1;
  int friction_directions = 2;  // tangent rows per point (SolverSettings::friction_directions)
};

// Appends the normal rows of one contact, then (in a later call, once every
// normal row of the island exists) its friction and rolling rows, recording
// their absolute indices in it; `island_begin` is the index of the island's
// first row. Islands list all normal rows before any friction row, as ODE
// and Bullet do: each sweep then bounds friction by this sweep's normal
// impulses.
void buildContactNormalRows(Contact& c, std::int32_t contact_index, const BodyView& a, const BodyView& b,
                            const ContactRowSettings& s, std::vector<ConstraintRow>& rows);
void buildContactFrictionRows(Contact& c, std::int32_t contact_index, const BodyView& a, const BodyView& b,
                              const ContactRowSettings& s, std::int32_t island_begin, std::vector<ConstraintRow>& rows);

// After the solve: keep the impulses for the next (sub)step.
void storeContactImpulses(Contact& c, const std::vector<ConstraintRow>& rows);

}  // namespace cairn
