// A motorized hinge door that breaks under a hit. The door (1 m wide, 2 m
// tall, 20 kg) hangs on a vertical hinge at its edge; a motor (target
// 1 rad/s, at most 20 N m) swings it open until its limit at 90 degrees
// stops it. A 5 kg ball thrown at 12 m/s then hits it; the hinge's
// break_force (the engine's breakable joints: JointDef::break_force) is
// 600 N, three times the door's weight, so the hinge holds the door but
// not the hit, and the World reports a JointBreakEvent.
//
// Figures a test checks (tests/examples/):
//  - spin-up: the motor is saturated, so w(t) = tau t / I_hinge with
//    I_hinge = m (w^2 + d^2) / 12 + m (w/2)^2 (parallel axes); gravity is
//    along the hinge and adds no torque about it;
//  - the motor's speed once reached: 1 rad/s;
//  - at rest against the limit the hinge carries the door's weight m g;
//  - the break: the reported force is above 600 N;
//  - after the break, door and ball are free: their total momentum changes
//    by exactly (m_door + m_ball) g dt (contacts between them are internal).
#include <cairn/cairn.hpp>

#include <cmath>
#include <cstdio>

int main() {
  cairn::World world;  // no ground: the door hangs in the air on its hinge
  const double h = 1.0 / 60, m = 20, width = 1, height = 2, thick = 0.1;
  const double tau = 20, target = 1, break_force = 600;

  cairn::BodyDef door;
  door.name = "door";
  door.mass = m;
  door.position = {width / 2, 1, 0};
  door.shapes.push_back(cairn::ShapeDesc::box({width / 2, height / 2, thick / 2}));
  door.sleeping_allowed = false;
  const cairn::BodyId door_id = world.createBody(door);

  cairn::JointDef hinge;
  hinge.name = "hinge";
  hinge.type = cairn::JointType::Hinge;
  hinge.body_a = door_id;  // body_b: the world; angle and motor measure the door relative to it
  hinge.anchor = {0, 1, 0};
  hinge.axis = {0, 1, 0};
  hinge.limit.enabled = true;
  hinge.limit.lower = 0;
  hinge.limit.upper = cairn::kPi / 2;
  hinge.motor.enabled = true;
  hinge.motor.target_velocity = target;
  hinge.motor.max_force = tau;
  hinge.break_force = break_force;
  const cairn::JointId joint = world.createJoint(hinge);

  std::printf("mass %.17g\nwidth %.17g\nthickness %.17g\nmotor_torque %.17g\nmotor_target %.17g\n", m, width, thick,
              tau, target);
  std::printf("gravity %.17g\nbreak_force %.17g\nstep %.17g\n", -world.gravity().y(), break_force, h);
  // Spin-up: 6 steps (0.1 s), well before the motor reaches its target.
  for (int n = 0; n < 6; ++n) world.step(h);
  std::printf("spinup_time %.17g spinup_speed %.17g\n", world.time(), world.angularVelocity(door_id).y());
  for (int n = 0; n < 54; ++n) world.step(h);  // t = 1 s: at full speed, not yet at the limit
  std::printf("cruise_speed %.17g\n", world.angularVelocity(door_id).y());
  for (int n = 0; n < 120; ++n) world.step(h);  // t = 3 s: resting against the limit
  const cairn::JointFeedback held = world.jointFeedback(joint);
  std::printf("rest_angle %.17g rest_hinge_force %.17g\n",
              2 * std::atan2(world.transform(door_id).q.y(), world.transform(door_id).q.w()), held.force_b.norm());

  // The hit: a ball 1 m in front of the door's centre, thrown at it.
  const cairn::Transform pose = world.transform(door_id);
  const cairn::Vec3 normal = pose.q * cairn::Vec3::UnitZ();
  cairn::BodyDef ball;
  ball.name = "ball";
  ball.mass = 5;
  ball.position = pose.p + normal;
  ball.linear_velocity = -12 * normal;
  ball.ccd = true;  // 0.2 m per step against a 0.1 m door: without CCD it would pass through
  ball.shapes.push_back(cairn::ShapeDesc::sphere(0.1));
  ball.sleeping_allowed = false;
  const cairn::BodyId ball_id = world.createBody(ball);
  int broke_at = -1;
  for (int n = 0; n < 60 && broke_at < 0; ++n) {
    world.step(h);
    for (const cairn::JointBreakEvent& e : world.jointBreakEvents()) {
      std::printf("break step %d force %.17g torque %.17g\n", e.step, e.force, e.torque);
      broke_at = e.step;
    }
  }
  std::printf("broken %d\n", world.isBroken(joint) ? 1 : 0);
  // Free flight of the pair: momentum before and after half a second.
  const auto momentum = [&] {
    return cairn::Vec3(world.mass(door_id) * world.linearVelocity(door_id) +
                       world.mass(ball_id) * world.linearVelocity(ball_id));
  };
  world.step(h);
  const cairn::Vec3 p0 = momentum();
  const double t0 = world.time();
  for (int n = 0; n < 30; ++n) world.step(h);
  const cairn::Vec3 p1 = momentum();
  std::printf("free_mass %.17g\nfree_dt %.17g\n", world.mass(door_id) + world.mass(ball_id), world.time() - t0);
  std::printf("free_dp %.17g %.17g %.17g\n", p1.x() - p0.x(), p1.y() - p0.y(), p1.z() - p0.z());
}
