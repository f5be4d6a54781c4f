#include "dynamics/forces.hpp"

namespace cairn {

void applyForceAtPoint(Body& b, const Vec3& force, const Vec3& world_point) {
  b.force += force;
  b.torque += (world_point - b.position).cross(force);
}

void applyImpulseAtPoint(Body& b, const Vec3& impulse, const Vec3& world_point) {
  if (!b.isDynamic()) return;
  b.linear_velocity += b.allowedLinear(b.inv_mass * impulse);
  b.angular_velocity += b.inv_inertia_world * (world_point - b.position).cross(impulse);
}

SpringState applySpring(Body* a, const Vec3& local_a, Body* b, const Vec3& local_b,
                        Real rest_length, Real stiffness, Real damping) {
  SpringState s;
  s.world_anchor_a = a ? a->transform().apply(local_a) : local_a;
  s.world_anchor_b = b ? b->transform().apply(local_b) : local_b;
  const Vec3 d = s.world_anchor_b - s.world_anchor_a;
  s.length = d.norm();
  if (s.length < Real(1e-12)) return s;  // direction undefined: no force
  const Vec3 n = d / s.length;
  const Vec3 va = a ? a->velocityAt(s.world_anchor_a) : Vec3::Zero();
  const Vec3 vb = b ? b->velocityAt(s.world_anchor_b) : Vec3::Zero();
  const Real rate = n.dot(vb - va);
  const Vec3 f = (stiffness * (s.length - rest_length) + damping * rate) * n;  // pulls a to b
  if (a) applyForceAtPoint(*a, f, s.world_anchor_a);
  if (b) applyForceAtPoint(*b, -f, s.world_anchor_b);
  return s;
}

}  // namespace cairn
