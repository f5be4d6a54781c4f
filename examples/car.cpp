// A car: a chassis and four wheels on hinge joints whose motors drive the
// wheels, over a ramp. The motors turn the wheels at 20 rad/s (at most
// 150 N m each); the car rolls along +x, climbs an 8 degree ramp 1.1 m
// high, leaves its top edge, flies and lands.
//
// Figures a test checks (tests/examples/):
//  - on the flat at full speed the wheels roll without slipping: the
//    car's speed is w R;
//  - on the ramp the chassis rises by the ramp's height;
//  - in the air (no contact at all) the car's momentum changes by exactly
//    M g dt: the hinges act inside the car only;
//  - after landing the wheels are still on their axles (anchor separation)
//    and the car is upright.
#include <cairn/cairn.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

int main() {
  cairn::World world;
  using cairn::Vec3;
  cairn::BodyDef ground;
  ground.name = "ground";
  ground.type = cairn::BodyType::Static;
  ground.shapes.push_back(cairn::ShapeDesc::plane({0, 1, 0}, 0));
  world.createBody(ground);

  // The ramp: a static box tilted by a about z, its top face rising from
  // the ground at x = 10 to 8 sin(a) m at its far edge.
  const double a = 8 * cairn::kPi / 180, ramp_start = 10, half_length = 4, half_thick = 0.5;
  cairn::BodyDef ramp;
  ramp.name = "ramp";
  ramp.type = cairn::BodyType::Static;
  ramp.orientation = cairn::Quat(Eigen::AngleAxisd(a, Vec3::UnitZ()));
  ramp.position = {ramp_start + half_length * std::cos(a) + half_thick * std::sin(a),
                   half_length * std::sin(a) - half_thick * std::cos(a), 0};
  ramp.shapes.push_back(cairn::ShapeDesc::box({half_length, half_thick, 3}));
  world.createBody(ramp);
  const double ramp_height = 2 * half_length * std::sin(a);
  const double ramp_end = ramp_start + 2 * half_length * std::cos(a);

  const double radius = 0.35, speed = 20, torque = 150;
  cairn::BodyDef chassis;
  chassis.name = "chassis";
  chassis.mass = 100;
  chassis.position = {0, 0.75, 0};
  chassis.shapes.push_back(cairn::ShapeDesc::box({1.0, 0.2, 0.5}));
  chassis.sleeping_allowed = false;
  const cairn::BodyId body = world.createBody(chassis);
  std::vector<cairn::BodyId> parts = {body};
  std::vector<cairn::JointId> axles;
  for (const double x : {-0.8, 0.8})
    for (const double z : {-0.7, 0.7}) {
      cairn::BodyDef wheel;
      wheel.name = std::string("wheel_") + (x > 0 ? "front" : "rear") + (z > 0 ? "_left" : "_right");
      wheel.mass = 10;
      wheel.friction = 1;
      wheel.position = {x, radius, z};
      // A cylinder's axis is its local y: turn it onto z, the axle.
      wheel.orientation = cairn::Quat(Eigen::AngleAxisd(cairn::kPi / 2, Vec3::UnitX()));
      wheel.shapes.push_back(cairn::ShapeDesc::cylinder(radius, 0.1));
      wheel.sleeping_allowed = false;
      const cairn::BodyId w = world.createBody(wheel);
      parts.push_back(w);
      cairn::JointDef axle;
      axle.name = wheel.name + "_axle";
      axle.type = cairn::JointType::Hinge;
      axle.body_a = w;  // the motor drives the first body (the wheel) relative to the second (the chassis)
      axle.body_b = body;
      axle.anchor = wheel.position;
      axle.axis = Vec3::UnitZ();
      axle.motor.enabled = true;
      axle.motor.target_velocity = -speed;  // -z spin rolls the car towards +x
      axle.motor.max_force = torque;
      axles.push_back(world.createJoint(axle));
    }

  double mass = 0;
  for (const cairn::BodyId id : parts) mass += world.mass(id);
  const auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (const cairn::BodyId id : parts) p += world.mass(id) * world.linearVelocity(id);
    return p;
  };
  const auto airborne = [&] {
    for (const cairn::BodyId id : parts)
      if (!world.contacts(id).empty()) return false;
    return true;
  };

  const double h = 1.0 / 60;
  std::printf("radius %.17g\nwheel_speed %.17g\nmass %.17g\nstep %.17g\ngravity %.17g\n", radius, speed, mass, h,
              -world.gravity().y());
  std::printf("ramp_height %.17g\nramp_start %.17g\nramp_end %.17g\nride_height %.17g\n", ramp_height, ramp_start,
              ramp_end, chassis.position.y());
  double max_y = 0;
  bool flat_printed = false;
  std::vector<Vec3> p_after;       // momentum after each step
  std::vector<char> free_after;    // no contact after the step, past the ramp's top
  for (int n = 1; n <= 900; ++n) {
    world.step(h);
    const Vec3 x = world.centerOfMass(body);
    max_y = std::max(max_y, x.y());
    if (!flat_printed && x.x() > ramp_start - 3) {  // on the flat, 3 m before the ramp
      std::printf("flat t %.17g x %.17g speed %.17g wheel_spin %.17g\n", world.time(), x.x(),
                  world.linearVelocity(body).x(), world.angularVelocity(parts[1]).z());
      flat_printed = true;
    }
    p_after.push_back(momentum());
    free_after.push_back(x.x() > ramp_end - 1 && airborne() ? 1 : 0);
  }
  // The flight: the longest run of contact-free steps. Its first and last
  // two steps are left out, so that no speculative contact (one made
  // before touching) of take-off or landing acts inside the window.
  size_t best_first = 0, best_len = 0;
  for (size_t i = 0; i < free_after.size();) {
    size_t j = i;
    while (j < free_after.size() && free_after[j]) ++j;
    if (j - i > best_len) best_first = i, best_len = j - i;
    i = j + 1;
  }
  const int flight_steps = best_len > 5 ? static_cast<int>(best_len) - 4 : 0;
  const Vec3 dp = flight_steps > 0 ? Vec3(p_after[best_first + 2 + flight_steps] - p_after[best_first + 2]) : Vec3::Zero();
  double axle_error = 0;
  for (const cairn::JointId j : axles) axle_error = std::max(axle_error, world.jointError(j).linear);
  const Vec3 up = world.transform(body).q * Vec3::UnitY();
  std::printf("max_chassis_y %.17g\n", max_y);
  std::printf("flight steps %d dp %.17g %.17g %.17g\n", flight_steps, dp.x(), dp.y(), dp.z());
  std::printf("final x %.17g up_y %.17g axle_error %.17g speed %.17g\n", world.centerOfMass(body).x(), up.y(),
              axle_error, world.linearVelocity(body).x());
}
