// Stages 1, 4 and 7 of the step: forces into the accumulators, the
// velocity update v* = v + h M^-1 f (with the gyroscopic term and damping:
// dynamics/integrate.cpp), and the position update from the solved
// velocities (and, with split impulse, the pseudo-velocities that move the
// bodies out of penetration without adding momentum).
#include "dynamics/forces.hpp"
#include "dynamics/integrate.hpp"
#include "world/body_walk.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/step_stages.hpp"

#include <string>

namespace cairn::detail {

namespace {

bool frozen(const StepContext& ctx, size_t body) {
  const std::int32_t isl = ctx.body_island[body];
  return ctx.any_frozen && isl >= 0 && ctx.frozen_island[static_cast<size_t>(isl)];
}

// Runs fn(i) for every body slot: on the pool's threads when there are
// many (each body's update is its own).
template <class F>
void forBodies(WorldImpl& w, F&& fn) {
  const int count = static_cast<int>(w.bodies_.size());
  const auto range = [&](int begin, int end) {
    for (int i = begin; i < end; ++i) fn(static_cast<size_t>(i));
  };
  if (splitBodyWalk(w)) w.pool_->parallelFor(count, range);
  else range(0, count);
}

}  // namespace

void applyForces(WorldImpl& w, StepContext& ctx) {
  for (const Spring& s : w.springs_) {
    if (!s.alive) continue;
    Body* a = s.def.body_a.isWorld() ? nullptr : &w.body(s.def.body_a);
    Body* b = s.def.body_b.isWorld() ? nullptr : &w.body(s.def.body_b);
    applySpring(a, s.local_a, b, s.local_b, s.rest_length, s.def.stiffness, s.def.damping);
  }
  // Constant loads every step; a timed impulse at the start of the first
  // step that begins at or after its time (within round-off of the clock).
  const Real now = w.time_ + Real(1e-9) * ctx.h;
  for (Body& b : w.bodies_) {
    if (!b.alive || !b.isDynamic()) continue;
    if (b.constant_force != Vec3::Zero() || b.constant_torque != Vec3::Zero()) {
      b.force += b.constant_force;
      b.torque += b.constant_torque;
      b.asleep = false;
      b.sleep_timer = 0;
    }
    while (b.next_impulse < b.impulses.size() && b.impulses[b.next_impulse].time <= now) {
      const BodyDef::TimedImpulse& imp = b.impulses[b.next_impulse++];
      applyImpulseAtPoint(b, imp.impulse, imp.point.value_or(b.position));
      b.asleep = false;
      b.sleep_timer = 0;
    }
  }
}

void integrateVelocities(WorldImpl& w, StepContext& ctx) {
  const Real h = ctx.hs;
  ctx.orientation_offset.assign(w.bodies_.size(), Vec3::Zero());
  // A body whose gyroscopic solve fell short is marked here and reported
  // after, in body order (the reports are not made on the threads).
  ctx.body_flag.assign(w.bodies_.size(), 0);
  forBodies(w, [&](size_t i) {
    if (!ctx.moves(i)) return;
    Body& b = w.bodies_[i];
    if (!b.alive || b.asleep || !b.isDynamic() || frozen(ctx, i)) return;
    bool gyro_ok = true;
    ctx.orientation_offset[i] = integrateVelocity(b, w.gravity_, h, w.settings_.gyroscopic, &gyro_ok);
    if (!gyro_ok) ctx.body_flag[i] = 1;
    // Safety net: cap the spin rate (off by default). stableNorm: |w|^2
    // must not overflow for the very spins the cap is there to catch.
    if (w.settings_.max_angular_velocity < kInf) {
      const Real rate = b.angular_velocity.stableNorm();
      if (rate > w.settings_.max_angular_velocity) b.angular_velocity *= w.settings_.max_angular_velocity / rate;
    }
  });
  for (size_t i = 0; i < w.bodies_.size(); ++i)
    if (ctx.body_flag[i])
      w.diagnose(static_cast<std::int32_t>(i), "gyroscopic solve",
                 "implicit-midpoint gyroscopic step not solved to 1e-10 |L| (h |w| = " +
                     std::to_string(h * w.bodies_[i].angular_velocity.norm()) +
                     " rad): energy and |L| not conserved; substeps with h |w| < 1 restore it");
}

void integratePositions(WorldImpl& w, StepContext& ctx) {
  const Real h = ctx.hs;
  const OrientationIntegrator method = w.settings_.orientation;
  forBodies(w, [&](size_t i) {
    if (!ctx.moves(i)) return;
    Body& b = w.bodies_[i];
    if (!b.alive || b.asleep || b.type == BodyType::Static || frozen(ctx, i)) return;
    const std::int32_t si = ctx.solver_of_body[i];
    if (ctx.has_pseudo && b.isDynamic() && si > 0 && si <= ctx.dynamic_count) {
      // Positions move at v + v_pseudo; the state velocity stays v.
      const SolverBody& p = ctx.pseudo[static_cast<size_t>(si)];
      b.position += h * p.v;
      integratePosition(b, h, method, ctx.orientation_offset[i] + p.w);
    } else {
      integratePosition(b, h, method, ctx.orientation_offset[i]);
    }
  });
  ctx.has_pseudo = false;
}

}  // namespace cairn::detail
