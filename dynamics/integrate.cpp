#include "dynamics/integrate.hpp"

#include <cmath>
#include <limits>

namespace cairn {

// Backward Euler on the torque-free body-frame Euler equation
//   J (w1 - w0) + h w1 x (J w1) = 0,
// one Newton step from w0 with the Jacobian J + h (skew(w) J - skew(J w)).
// This is what Bullet calls the implicit body-frame gyroscopic impulse: it is
// unconditionally stable but removes kinetic energy from tumbling bodies.
Vec3 gyroscopicImplicitEuler(const Mat3& inertia, const Vec3& w, Real h) {
  const Vec3 l = inertia * w;
  const Vec3 f = h * w.cross(l);
  const Mat3 jac = inertia + h * (skew(w) * inertia - skew(l));
  return w - jac.lu().solve(f);
}

// The implicit midpoint rule in its rotation form: the body-frame angular
// momentum is carried back by the rotation of the step,
//   J w1 = exp(-h wm) J w0,  wm = (w0 + w1) / 2.
// Rotating L about wm leaves |L| unchanged, and wm . (L1 - L0) = 0 because
// the change of a vector rotated about wm is perpendicular to wm; with
// E = 1/2 w.J w that gives E1 - E0 = wm . (L1 - L0) = 0. Both invariants hold
// to round-off whatever the step -- once the equation is solved.
//
// Newton's method on F(w1) = J w1 - exp(theta) L0, theta = -h wm, with the
// exact Jacobian dF/dw1 = J - h/2 skew(exp(theta) L0) J_l(theta) (J_l: the
// left Jacobian of SO(3), d(exp(theta) v)/dtheta = -skew(exp(theta) v)
// J_l(theta)), and a backtracking line search that halves the step until
// |F| falls. The first-order Jacobian J - h/2 skew(L0) used before is exact
// only for small h |w|: on a thin rod (inertia ratio 5000) at 1000 rad/s it
// stalled and the energy grew by up to 570% (docs/extremes.md).
namespace {

Mat3 leftJacobianSO3(const Vec3& theta) {
  const Real a2 = theta.squaredNorm(), a = std::sqrt(a2);
  const Mat3 k = skew(theta);
  Real c1, c2;  // (1 - cos a) / a^2 and (a - sin a) / a^3
  if (a < Real(1e-4)) {
    c1 = Real(0.5) - a2 / 24;
    c2 = Real(1) / 6 - a2 / 120;
  } else {
    c1 = (1 - std::cos(a)) / a2;
    c2 = (a - std::sin(a)) / (a2 * a);
  }
  return Mat3::Identity() + c1 * k + c2 * k * k;
}

}  // namespace

Vec3 gyroscopicImplicitMidpoint(const Mat3& inertia, const Vec3& w0, Real h, bool* converged) {
  const Vec3 l0 = inertia * w0;
  const auto residualAt = [&](const Vec3& w1) {
    return Vec3(inertia * w1 - quatFromRotationVector(-h * Real(0.5) * (w0 + w1)) * l0);
  };
  const Real tol = Real(1e-14) * (l0.norm() + std::numeric_limits<Real>::min());
  Vec3 w1 = w0;
  Vec3 f = residualAt(w1);
  Real fn = f.norm();
  for (int it = 0; it < 50 && fn > tol; ++it) {
    const Vec3 theta = -h * Real(0.5) * (w0 + w1);
    const Vec3 rl = quatFromRotationVector(theta) * l0;
    const Mat3 jac = inertia - Real(0.5) * h * skew(rl) * leftJacobianSO3(theta);
    const Vec3 step = jac.lu().solve(f);
    Real alpha = 1;
    Vec3 trial = w1 - step;
    Vec3 ft = residualAt(trial);
    for (int k = 0; k < 30 && !(ft.norm() < fn); ++k) {
      alpha *= Real(0.5);
      trial = w1 - alpha * step;
      ft = residualAt(trial);
    }
    if (!(ft.norm() < fn)) break;  // no descent: stuck
    w1 = trial;
    f = ft;
    fn = ft.norm();
  }
  // Round-off of the rotation itself is ~1e-16 |L|; call it solved within
  // 1e-10 |L| (energy and |L| then hold to that relative accuracy).
  if (converged) *converged = std::isfinite(fn) && fn <= Real(1e-10) * (l0.norm() + std::numeric_limits<Real>::min());
  return w1;
}

Vec3 integrateVelocity(Body& b, const Vec3& gravity, Real h, Gyroscopic gyro, bool* gyro_converged) {
  if (!b.isDynamic()) return Vec3::Zero();
  // Degree-of-freedom locks: the projected inverse mass (linear_factor) and
  // inverse inertia (already projected in inv_inertia_world) keep every
  // acceleration off the locked axes, gravity included.
  b.linear_velocity += h * b.allowedLinear(gravity + b.inv_mass * b.force);
  b.angular_velocity += h * (b.inv_inertia_world * b.torque);

  Vec3 orientation_offset = Vec3::Zero();
  // A body whose principal moments are equal (a cube, a sphere: J = c 1)
  // has no gyroscopic torque, w x (c w) = 0, and every scheme below has
  // w1 = w0 for its exact solution (the midpoint rule's exp(-h wm) turns
  // c w0 about w0 itself). Skipping them saves two rotations by exp-map
  // (six trigonometric calls) per body and step; the schemes would only add
  // round-off.
  if (isIsotropic(b.inertia_body)) gyro = Gyroscopic::Off;
  if (b.rotation_locked) {
    // Rotation locks: the constrained Euler equation is
    // B^T (I dw/dt + w x I w) = B^T tau (B a basis of the free rotations,
    // dynamics/body.hpp), so the gyroscopic torque acts through the locked
    // inverse inertia W = B (B^T I B)^-1 B^T, here explicitly. With one
    // free axis a and w = u a its part along a, a . (a x I a) u^2, is zero:
    // a planar body's spin is exact. The unconstrained schemes below would
    // let the body wobble off the free axis and then lose that motion to
    // the projection, changing the free spin.
    if (gyro != Gyroscopic::Off)
      b.angular_velocity -= h * (b.inv_inertia_world * b.angular_velocity.cross(b.angularMomentum()));
    gyro = Gyroscopic::Off;
  }
  switch (gyro) {
    case Gyroscopic::Off:
      break;
    case Gyroscopic::Explicit: {
      const Vec3 l = b.angularMomentum();
      b.angular_velocity -= h * (b.inv_inertia_world * b.angular_velocity.cross(l));
      break;
    }
    case Gyroscopic::ImplicitEuler: {
      const Vec3 wb = b.rotation.transpose() * b.angular_velocity;
      b.angular_velocity = b.rotation * gyroscopicImplicitEuler(b.inertia_body, wb, h);
      break;
    }
    case Gyroscopic::ImplicitMidpoint: {
      // The midpoint rule advances the orientation with wm, R1 = R0 exp(h wm),
      // which undoes exactly the rotation applied to the body-frame L above,
      // so the world-frame L = R J w stays fixed. w1 is a body-frame velocity
      // at the end of the step, so its world value is R1 w1, and the
      // difference between the orientation rate (R0 wm) and the state
      // velocity is handed to the position stage as an offset; constraint
      // impulses still act on the state velocity.
      const Vec3 wb0 = b.rotation.transpose() * b.angular_velocity;
      const Vec3 wb1 = gyroscopicImplicitMidpoint(b.inertia_body, wb0, h, gyro_converged);
      const Vec3 wbm = Real(0.5) * (wb0 + wb1);
      b.angular_velocity = b.rotation * (quatFromRotationVector(h * wbm) * wb1);
      orientation_offset = b.rotation * wbm - b.angular_velocity;
      break;
    }
  }

  // W's range is the free rotations; this removes only round-off.
  if (b.rotation_locked) b.angular_velocity = b.allowedAngular(b.angular_velocity);

  // Linear damping as an implicit decay, stable for any h c.
  if (b.linear_damping > 0) b.linear_velocity /= (1 + h * b.linear_damping);
  if (b.angular_damping > 0) b.angular_velocity /= (1 + h * b.angular_damping);
  return orientation_offset;
}

void integratePosition(Body& b, Real h, OrientationIntegrator method,
                       const Vec3& orientation_offset) {
  if (b.type == BodyType::Static) return;
  b.position += h * b.linear_velocity;
  const Vec3 w = b.angular_velocity + orientation_offset;
  if (method == OrientationIntegrator::ExponentialMap) {
    b.orientation = quatFromRotationVector(h * w) * b.orientation;
  } else {
    const Quat wq(0, w.x(), w.y(), w.z());
    b.orientation.coeffs() += Real(0.5) * h * (wq * b.orientation).coeffs();
  }
  b.orientation.normalize();
  b.updateDerived();
}

}  // namespace cairn
