// Semi-implicit Euler (section 12.6.3): velocities first, from forces and
// gravity, then positions from the new velocities. Orientation follows the
// angular velocity by the exponential map or by the quaternion derivative
// q' = 1/2 w q (section 12.6.4).
#pragma once

#include "cairn/settings.hpp"
#include "dynamics/body.hpp"

namespace cairn {

// v* = v + h (g + f / m), w* = w + h J_w^-1 tau, then the gyroscopic term
// by `gyro`, then damping v *= 1 / (1 + h c). Only dynamic bodies change.
// Returns the world-frame angular velocity offset that the position stage
// must add for the orientation to advance at the midpoint velocity
// (non-zero only for Gyroscopic::ImplicitMidpoint; see integrate.cpp).
// `gyro_converged` (optional) reports the implicit-midpoint solve's outcome.
Vec3 integrateVelocity(Body& b, const Vec3& gravity, Real h, Gyroscopic gyro, bool* gyro_converged = nullptr);

// x += h v; q advanced by h (w + orientation_offset); derived data refreshed.
// Static bodies do not move; kinematic and dynamic bodies do.
void integratePosition(Body& b, Real h, OrientationIntegrator method,
                       const Vec3& orientation_offset = Vec3::Zero());

// Body-frame angular velocity after one torque-free gyroscopic step of each
// kind, exposed for tests and docs. `w` and the result are body-frame.
Vec3 gyroscopicImplicitEuler(const Mat3& inertia, const Vec3& w, Real h);
// `converged` (optional) is set false when Newton's method could not solve
// the midpoint equation to 1e-10 |L|: the step then does not conserve E and
// |L| to round-off, and the caller should say so.
Vec3 gyroscopicImplicitMidpoint(const Mat3& inertia, const Vec3& w, Real h, bool* converged = nullptr);

}  // namespace cairn
