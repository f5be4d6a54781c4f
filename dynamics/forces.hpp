// Force generators that feed the accumulators before the velocity update.
#pragma once

#include "dynamics/body.hpp"

namespace cairn {

// Force f applied at a world point: adds f and the torque r x f about the
// center of mass (section 12.5.3).
void applyForceAtPoint(Body& b, const Vec3& force, const Vec3& world_point);

// Impulse p at a world point: changes v by p/m and w by J_w^-1 (r x p)
// immediately (section 12.5.4). Only dynamic bodies respond.
void applyImpulseAtPoint(Body& b, const Vec3& impulse, const Vec3& world_point);

// A spring-damper between a point on body a and a point on body b (section
// 12.2.3): Hooke's force k (L - L0) along the line between the points plus
// damping c times the rate of change of L. Either body may be null (the
// world), then its anchor is a fixed world point.
struct SpringState {
  Vec3 world_anchor_a, world_anchor_b;  // current anchor positions
  Real length;                          // current length
};

SpringState applySpring(Body* a, const Vec3& local_a, Body* b, const Vec3& local_b,
                        Real rest_length, Real stiffness, Real damping);

// Potential energy 1/2 k (L - L0)^2 of a spring at its current state.
inline Real springEnergy(Real length, Real rest_length, Real stiffness) {
  const Real d = length - rest_length;
  return Real(0.5) * stiffness * d * d;
}

}  // namespace cairn
