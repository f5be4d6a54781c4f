// A game loop: frames of varying length (a renderer at no fixed rate) drive
// the world through the FixedStepDriver at h = 1/60 s, and each frame draws
// the interpolated poses. A kinematic platform moves along +x at 1 m/s
// from rest; a box resting on it is dragged along by friction.
//
// What it prints, and the physics a test checks (tests/examples/):
//  - steps = floor(total frame time / h) (no cap hit): the accumulator;
//  - the platform's drawn x equals x0 + v t at the frame's render time
//    (a kinematic body moves exactly at its velocity, and the
//    interpolation is linear in time);
//  - the box slips back on the platform by v^2 / (2 mu g) before it
//    catches up (it accelerates at mu g while the platform does not wait),
//    then rides at v.
#include <cairn/cairn.hpp>

#include <cstdio>

int main() {
  cairn::World world;
  cairn::BodyDef ground;
  ground.name = "ground";
  ground.type = cairn::BodyType::Static;
  ground.shapes.push_back(cairn::ShapeDesc::plane({0, 1, 0}, 0));
  world.createBody(ground);

  cairn::BodyDef platform;
  platform.name = "platform";
  platform.type = cairn::BodyType::Kinematic;
  platform.position = {0, 1, 0};
  platform.shapes.push_back(cairn::ShapeDesc::box({3, 0.25, 2}));
  const cairn::BodyId plat = world.createBody(platform);
  const cairn::Vec3 v(1, 0, 0);  // m/s
  world.setKinematicVelocity(plat, v, cairn::Vec3::Zero());

  cairn::BodyDef crate;
  crate.name = "crate";
  crate.mass = 1;
  crate.position = {0, 1.75, 0};  // resting on the platform's top face, y = 1.25
  crate.shapes.push_back(cairn::ShapeDesc::box({0.5, 0.5, 0.5}));
  const cairn::BodyId box = world.createBody(crate);

  cairn::FixedStepDriver driver(world, {1.0 / 60, 8});
  // A renderer's uneven frame times (s): vsync at 30, 144 and 75 Hz, a
  // hitch, a fast frame.
  const double frames[] = {1.0 / 30, 1.0 / 144, 1.0 / 75, 0.021, 0.0042, 0.05};
  double total = 0;
  std::printf("step %.17g\nfriction %.17g\ngravity %.17g\nplatform_speed %.17g\nplatform_x0 %.17g\n",
              driver.settings().step, 0.5, -world.gravity().y(), v.x(), platform.position.x());
  for (int frame = 0; frame < 360; ++frame) {
    const double dt = frames[frame % 6];
    total += dt;
    driver.advance(dt);
    if (frame % 30 == 29) {
      const cairn::Transform p = driver.interpolatedTransform(plat);
      const cairn::Transform b = driver.interpolatedTransform(box);
      std::printf("frame %d render_time %.17g platform_x %.17g crate_x %.17g crate_y %.17g\n", frame + 1,
                  driver.renderTime(), p.p.x(), b.p.x(), b.p.y());
    }
  }
  const double slip = (world.transform(box).p.x() - crate.position.x()) -
                      (world.transform(plat).p.x() - platform.position.x());
  std::printf("total_frame_time %.17g\nsteps %lld\ndropped %.17g\nworld_time %.17g\n", total,
              static_cast<long long>(driver.steps()), driver.droppedTime(), world.time());
  std::printf("crate_speed %.17g\nslip %.17g\n", world.linearVelocity(box).x(), slip);
}
