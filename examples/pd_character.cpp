// A character pushed by a PD controller: an upright capsule that cannot
// tip (its rotations are locked), frictionless on the ground, driven to a
// target by the force
//     F = kp (x_target - x) - kd v,
// a spring with a damper pulling it to the target: the damped spring of
// section 12.2.3 of Dunn and Parberry's "3D Math Primer for Graphics and
// Game Development", 2nd ed. With kp = m w^2 and kd = 2 m w the controller
// is critically damped: x(t) = x_t - (x_t - x0)(1 + w t) e^(-w t), the
// fastest approach that never overshoots.
//
// The force is applied before each step and acts over it, so the engine's
// semi-implicit Euler gives the recurrence
//     v' = v + h F(x, v) / m,  x' = x + h v',
// which a test (tests/examples/) replays exactly and also compares with the
// closed form.
#include <cairn/cairn.hpp>

#include <cstdio>

int main() {
  cairn::World world;
  cairn::BodyDef ground;
  ground.name = "ground";
  ground.type = cairn::BodyType::Static;
  ground.friction = 0;
  ground.shapes.push_back(cairn::ShapeDesc::plane({0, 1, 0}, 0));
  world.createBody(ground);

  const double mass = 80, radius = 0.3, half_height = 0.6;
  cairn::BodyDef hero;
  hero.name = "character";
  hero.mass = mass;
  hero.friction = 0;  // the controller alone moves it sideways
  hero.position = {0, radius + half_height, 0};  // standing on the ground
  hero.shapes.push_back(cairn::ShapeDesc::capsule(radius, half_height));
  hero.lock_rotation = {cairn::Vec3::UnitX(), cairn::Vec3::UnitY(), cairn::Vec3::UnitZ()};
  hero.sleeping_allowed = false;
  const cairn::BodyId id = world.createBody(hero);

  const double w = 3;  // rad/s: the controller's natural frequency
  const double kp = mass * w * w, kd = 2 * mass * w;
  const double target = 4, h = 1.0 / 60;
  std::printf("mass %.17g\nkp %.17g\nkd %.17g\nomega %.17g\ntarget %.17g\nstep %.17g\nx0 %.17g\n", mass, kp, kd, w,
              target, h, hero.position.x());
  for (int n = 1; n <= 240; ++n) {
    const double x = world.transform(id).p.x(), v = world.linearVelocity(id).x();
    world.applyCentralForce(id, {kp * (target - x) - kd * v, 0, 0});
    world.step(h);
    if (n % 15 == 0)
      std::printf("n %d x %.17g v %.17g y %.17g\n", n, world.transform(id).p.x(), world.linearVelocity(id).x(),
                  world.transform(id).p.y());
  }
}
