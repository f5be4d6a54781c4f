// The step pipeline (../shared/ARCHITECTURE.md, Listing 12.6 of the seed
// chapter), top to bottom:
//
//   1. forces       springs and user forces into the accumulators
//   2. velocities   v* = v + h M^-1 f (gravity, gyroscopic term, damping)
//   3. collision    broadphase -> narrowphase -> contact manifolds
//   4. rows         contacts, joints, limits, motors -> Jacobian rows
//   5. solve        lambda from the rows; v = v* + M^-1 J^T lambda
//   6. positions    x += h v, q <- exp(h w) q
//   7. clean up     clear accumulators; guard against non-finite state
//
// Stages 3 to 5 are filled by the collision and constraint modules.
#include "dynamics/error.hpp"
#include "dynamics/forces.hpp"
#include "dynamics/integrate.hpp"
#include "world/world.hpp"

#include <chrono>
#include <cmath>

namespace cairn {

void World::step(Real h) {
  if (!std::isfinite(h) || h <= 0)
    throw InputError("world", "dt", "time step must be positive and finite (got " + std::to_string(h) + ")");
  const auto t0 = std::chrono::steady_clock::now();
  saveStepStart();

  applyExternalForces();                                  // 1
  integrateVelocities(h);                                 // 2
  guardFinite("velocity integration");
  // 3-5: collision, constraint rows and the solver arrive with their issues.
  integratePositions(h);                                  // 6
  guardFinite("position integration");
  clearAccumulators();                                    // 7

  ++step_count_;
  time_ += h;
  stats_.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void World::applyExternalForces() {
  for (const auto& s : springs_) {
    Body* a = s.def.body_a.isWorld() ? nullptr : &body(s.def.body_a);
    Body* b = s.def.body_b.isWorld() ? nullptr : &body(s.def.body_b);
    applySpring(a, s.local_a, b, s.local_b, s.rest_length, s.def.stiffness, s.def.damping);
  }
}

void World::integrateVelocities(Real h) {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    orientation_offset_[i] = integrateVelocity(bodies_[i], gravity_, h, settings_.gyroscopic);
    Body& b = bodies_[i];
    // Safety net: cap the spin rate (off by default).
    const Real w = b.angular_velocity.norm();
    if (w > settings_.max_angular_velocity) b.angular_velocity *= settings_.max_angular_velocity / w;
  }
}

void World::integratePositions(Real h) {
  for (size_t i = 0; i < bodies_.size(); ++i)
    integratePosition(bodies_[i], h, settings_.orientation, orientation_offset_[i]);
}

void World::clearAccumulators() {
  for (auto& b : bodies_) {
    b.force.setZero();
    b.torque.setZero();
  }
}

void World::saveStepStart() {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    step_start_[i] = {b.position, b.orientation, b.linear_velocity, b.angular_velocity};
  }
}

void World::restoreBody(size_t i) {
  Body& b = bodies_[i];
  b.position = step_start_[i].x;
  b.orientation = step_start_[i].q;
  b.linear_velocity.setZero();
  b.angular_velocity.setZero();
  b.force.setZero();
  b.torque.setZero();
  b.updateDerived();
}

// No NaN leaves a step silently: a body whose state went non-finite is put
// back where it was at the start of the step, at rest, and the event names
// the body and the stage. The rest of the world is untouched.
bool World::guardFinite(const char* stage) {
  bool ok = true;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    if (b.position.allFinite() && b.orientation.coeffs().allFinite() && b.linear_velocity.allFinite() &&
        b.angular_velocity.allFinite())
      continue;
    restoreBody(i);
    numerical_events_.push_back({step_count_, BodyId{static_cast<std::int32_t>(i)}, b.name, stage});
    ok = false;
  }
  return ok;
}

}  // namespace cairn
