// The World: owns bodies, shapes, springs, joints and settings, hands out
// integer handles, and runs the step pipeline of ../shared/ARCHITECTURE.md
// (world/world_step.cpp reads top to bottom as that pipeline).
#pragma once

#include "constraints/joint.hpp"
#include "constraints/row.hpp"
#include "dynamics/body.hpp"
#include "solver/solver_body.hpp"
#include "world/defs.hpp"
#include "world/settings.hpp"

#include <string>
#include <vector>

namespace cairn {

struct Spring {
  SpringDef def;
  Vec3 local_a, local_b;  // anchors in the body frames (world points for the world)
  Real rest_length;
};

// What a step reports about itself (the solver's quality, MuJoCo-style).
struct StepStats {
  int iterations = 0;      // PGS sweeps done (summed over substeps)
  Real residual = 0;       // natural-map LCP residual after the solve (max norm, last substep)
  int rows = 0;            // rows solved (last substep)
  int rows_by_kind[kRowKindCount] = {};
  double wall_seconds = 0;
};

// A joint that broke: its force or torque exceeded its threshold.
struct JointBreakEvent {
  int step = 0;
  JointId joint;
  std::string name;
  Real force = 0, torque = 0;
};

// A non-finite value caught by the guard: which body and which stage.
struct NumericalEvent {
  int step = 0;
  BodyId body;
  std::string body_name;
  std::string stage;
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
  void buildRows(Real h);
  void solveRows();
  void storeImpulses(Real h);
  void clearAccumulators();
  bool guardFinite(const char* stage);
  void saveStepStart();
  void restoreBody(size_t i);

  Vec3 gravity_ = Vec3(0, Real(-9.81), 0);
  SolverSettings settings_;
  std::vector<Body> bodies_;
  std::vector<Spring> springs_;
  std::vector<Joint> joints_;

  // Per-step working arrays (sized once, reused: no allocation per step).
  std::vector<Vec3> orientation_offset_;
  struct SavedState { Vec3 x; Quat q; Vec3 v; Vec3 w; };
  std::vector<SavedState> step_start_;
  std::vector<ConstraintRow> rows_;
  std::vector<SolverBody> solver_bodies_;
  std::vector<SolverBody> pseudo_bodies_;  // split-impulse pseudo-velocities (index as solver bodies)
  std::vector<Real> pseudo_lambda_;
  std::vector<std::int32_t> order_scratch_;
  std::uint64_t rng_state_ = 0;
  bool rng_seeded_ = false;

  int step_count_ = 0;
  Real time_ = 0;
  StepStats stats_;
  std::vector<NumericalEvent> numerical_events_;
  std::vector<JointBreakEvent> break_events_;
};

void validateSettings(const SolverSettings& s);

}  // namespace cairn
