// The World: owns bodies, shapes, springs, joints and settings, hands out
// integer handles, and runs the step pipeline of ../shared/ARCHITECTURE.md
// (world/world_step.cpp reads top to bottom as that pipeline).
#pragma once

#include "collision/broadphase.hpp"
#include "collision/manifold.hpp"
#include "constraints/contact.hpp"
#include "constraints/joint.hpp"
#include "constraints/row.hpp"
#include "dynamics/body.hpp"
#include "solver/direct_solver.hpp"
#include "solver/pgs.hpp"
#include "solver/solver_body.hpp"
#include "cairn/defs.hpp"
#include "cairn/settings.hpp"
#include "cairn/stats.hpp"

#include <functional>
#include <string>
#include <vector>

namespace cairn {

struct Spring {
  SpringDef def;
  Vec3 local_a, local_b;  // anchors in the body frames (world points for the world)
  Real rest_length;
};

// A joint that broke: its force or torque exceeded its threshold.
struct JointBreakEvent {
  int step = 0;
  JointId joint;
  std::string name;
  Real force = 0, torque = 0;
};

// Contacts begun and ended, for sounds and damage: read after the step.
struct ContactEvent {
  enum class Type { Begin, End } type = Type::Begin;
  int step = 0;
  BodyId body_a, body_b;
  std::int32_t shape_a = -1, shape_b = -1;
  Vec3 point = Vec3::Zero();   // deepest point (world)
  Vec3 normal = Vec3::Zero();  // from a to b
  Real impulse = 0;            // total normal impulse of the step (N s); 0 for End
};

// What a contact callback sees and may change, once per manifold per step
// before any row is built: veto (enabled = false, e.g. a one-way platform),
// or change friction and restitution for this contact.
struct ContactInfo {
  BodyId body_a, body_b;
  std::int32_t shape_a = -1, shape_b = -1;
  Vec3 normal = Vec3::Zero();  // from a to b
  int count = 0;
  Vec3 points[4];
  Real depths[4] = {};
  Vec3 relative_velocity = Vec3::Zero();  // of b's deepest point relative to a's
  Real friction = 0, restitution = 0;
  bool enabled = true;
};
using ContactCallback = std::function<void(ContactInfo&)>;

// A shape in the World: which body and which of its shapes, and its
// broadphase proxy.
struct ShapeRef {
  BodyId body;
  std::int32_t index = 0;
  std::int32_t proxy = -1;
};

// A non-finite value caught by the guard (docs/extremes.md, "Safety nets").
// The guard stops the step for the island it appeared in: every awake
// dynamic body of that island goes back to its state at the start of the
// step, at rest, and stays there for the rest of the step; other islands
// keep stepping. Stages, in step order: "step start" (a state set through
// the API between steps), "velocity integration", "row building",
// "constraint solve", "position integration".
struct NumericalEvent {
  int step = 0;
  BodyId body;            // the body found non-finite (for a row: its dynamic body)
  std::string body_name;
  std::string stage;
  std::int32_t island = -1;  // island index of this step; -1: the body was in none (kinematic, or at step start)
  int bodies_restored = 0;   // bodies put back to their step-start state
  std::string detail;        // what was non-finite, e.g. "linear velocity" or "joint 'hinge' row 1: rhs"
};

// A step the engine took but could not take accurately, reported rather
// than passed on silently (docs/extremes.md, "Safety nets"). One entry per
// body and kind, counting the (sub)steps it happened in. Kinds:
//   "gyroscopic solve"  the implicit-midpoint gyroscopic step did not solve
//                       its equation to 1e-10 |L| (h |w| too large for the
//                       body's inertia ratio): energy and angular momentum
//                       are not conserved in those steps; substeps with
//                       h |w| < 1 restore it.
struct Diagnostic {
  BodyId body;
  std::string body_name;
  std::string kind;
  std::string detail;
  int first_step = 0;
  int count = 0;  // how many (sub)steps it happened in
};

class World {
 public:
  World() = default;
  explicit World(const Vec3& gravity) : gravity_(gravity) {}

  // --- Creation: validates the whole definition first, then creates. On bad
  // input throws InputError and leaves the world unchanged.
  BodyId createBody(const BodyDef& def);
  int createSpring(const SpringDef& def);
  JointId createJoint(const JointDef& def);

  // --- Access
  int bodyCount() const { return static_cast<int>(bodies_.size()); }
  const Body& body(BodyId id) const { return bodies_.at(static_cast<size_t>(id.index)); }
  Body& body(BodyId id) { return bodies_.at(static_cast<size_t>(id.index)); }
  const std::vector<Body>& bodies() const { return bodies_; }
  BodyId findBody(const std::string& name) const;
  const std::vector<Spring>& springs() const { return springs_; }
  int jointCount() const { return static_cast<int>(joints_.size()); }
  const Joint& joint(JointId id) const { return joints_.at(static_cast<size_t>(id.index)); }
  JointId findJoint(const std::string& name) const;
  // A joint's constraint force and torque on each body over the last step
  // (lambda / h mapped back through J); zero once broken.
  const JointFeedback& jointFeedback(JointId id) const { return joint(id).feedback; }
  JointError jointError(JointId id) const;
  void removeJoint(JointId id);  // the joint stops acting (its handle stays valid)
  // The rows of the last (sub)step, for inspection and the exact solvers.
  const std::vector<ConstraintRow>& rows() const { return rows_; }

  // --- Forces (accumulate until the end of the next step) and impulses.
  void applyForce(BodyId id, const Vec3& force, const Vec3& world_point);
  void applyCentralForce(BodyId id, const Vec3& force);
  void applyTorque(BodyId id, const Vec3& torque);
  void applyImpulse(BodyId id, const Vec3& impulse, const Vec3& world_point);
  // Scripted motion of a kinematic body.
  void setKinematicVelocity(BodyId id, const Vec3& linear, const Vec3& angular);

  // --- Contacts
  const std::vector<Contact>& contacts() const { return contacts_; }
  const std::vector<ContactEvent>& contactEvents() const { return contact_events_; }
  void setContactCallback(ContactCallback cb) { contact_callback_ = std::move(cb); }
  // Friction and restitution for one body pair, replacing the combination
  // (geometric-mean friction, larger restitution).
  void setPairMaterial(BodyId a, BodyId b, Real friction, Real restitution);
  const std::vector<ShapeRef>& shapes() const { return shapes_; }
  const BroadPhase& broadPhase() const { return broadphase_; }
  // Deepest penetration among touching contacts now (m, >= 0).
  Real maxPenetration() const;

  // --- Sleeping
  void wakeBody(BodyId id);
  bool isAsleep(BodyId id) const { return body(id).asleep; }

  // --- Settings
  const Vec3& gravity() const { return gravity_; }
  void setGravity(const Vec3& g);
  SolverSettings& settings() { return settings_; }
  const SolverSettings& settings() const { return settings_; }
  // Validates and sets (throws InputError naming "solver" and the field).
  void setSettings(const SolverSettings& s);

  // --- Stepping
  void step(Real h);
  int stepCount() const { return step_count_; }
  Real time() const { return time_; }
  const StepStats& lastStepStats() const { return stats_; }
  // Non-finite states caught and rolled back (never silently passed on).
  const std::vector<NumericalEvent>& numericalEvents() const { return numerical_events_; }
  // Steps taken but not taken accurately (Diagnostic above), since creation.
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }
  // Joints broken during the last step.
  const std::vector<JointBreakEvent>& jointBreakEvents() const { return break_events_; }

  // --- Energy bookkeeping for tests and metrics.
  Real kineticEnergy() const;
  Real potentialEnergy() const;  // gravity (relative to y = 0 along -g) + springs
  Vec3 linearMomentum() const;

 private:
  void applyExternalForces();
  void integrateVelocities(Real h);
  void integratePositions(Real h);
  BodyView view(BodyId id) const;
  void registerShapes(BodyId id);
  void detectContacts(Real h);
  bool shouldCollide(const Body& a, const Body& b, BodyId ia, BodyId ib) const;
  void emitContactEvents(const std::vector<Contact>& old);
  void buildIslands();
  void updateSleep(Real h);
  void wakeIsland(std::int32_t island);
  void buildRows(Real h);
  void solveRows();
  void storeImpulses(Real h);
  void clearAccumulators();
  // The NaN/Inf guard (world/world_step.cpp).
  void saveStepStart();
  void saveStepEnd();
  void guardBodies(const char* stage);
  void guardRows(const char* stage);
  void guardIslandSolve(std::int32_t begin, std::int32_t end);
  void freezeIsland(std::int32_t island, size_t body, const char* stage, std::string detail);
  void holdFrozen();
  void restoreBody(size_t i);

  Vec3 gravity_ = Vec3(0, Real(-9.81), 0);
  SolverSettings settings_;
  std::vector<Body> bodies_;
  std::vector<Spring> springs_;
  std::vector<Joint> joints_;
  std::vector<ShapeRef> shapes_;
  BroadPhase broadphase_;
  std::vector<Contact> contacts_;       // sorted by key
  std::vector<Contact> old_contacts_;   // scratch: last step's, for matching
  std::vector<std::pair<int, int>> pairs_;
  std::vector<Manifold> manifolds_;
  std::vector<ContactEvent> contact_events_;
  ContactCallback contact_callback_;
  struct PairMaterial { std::uint64_t key; Real friction, restitution; };
  std::vector<PairMaterial> pair_materials_;  // sorted by key
  // Islands: per body (dynamic, awake) its island, -1 otherwise; rows are
  // built island by island and island_rows_ holds each island's range.
  std::vector<std::int32_t> body_island_;
  std::vector<std::int32_t> uf_parent_;
  std::vector<std::pair<std::int32_t, std::int32_t>> island_rows_;
  std::vector<std::int32_t> sleep_island_;  // per body: the island it fell asleep with
  int island_count_ = 0;

  // Per-step working arrays (sized once, reused: no allocation per step).
  std::vector<Vec3> orientation_offset_;
  struct SavedState { Vec3 x; Quat q; Vec3 v; Vec3 w; };
  std::vector<SavedState> step_start_;  // last good state: the step's start (or, between steps, the last end)
  std::vector<char> frozen_island_;     // per island of this step: stopped by the guard
  bool any_frozen_ = false;
  std::vector<ConstraintRow> rows_;
  std::vector<SolverBody> solver_bodies_;
  std::vector<SolverBody> pseudo_bodies_;  // split-impulse pseudo-velocities (index as solver bodies)
  std::vector<Real> pseudo_lambda_;
  PgsScratch pgs_scratch_;
  DirectSolver direct_solver_;  // keeps CHOLMOD's symbolic analysis while the structure holds
  std::uint64_t rng_state_ = 0;
  bool rng_seeded_ = false;

  int step_count_ = 0;
  Real time_ = 0;
  StepStats stats_;
  std::vector<NumericalEvent> numerical_events_;
  std::vector<Diagnostic> diagnostics_;
  void diagnose(size_t body, const char* kind, const std::string& detail);
  std::vector<JointBreakEvent> break_events_;
};

void validateSettings(const SolverSettings& s);

}  // namespace cairn
