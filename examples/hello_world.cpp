// Hello world: a 1 m box falls from 30 m onto the ground and prints its
// height once a second, beside the free-fall closed form
// y(t) = y0 - g t^2 / 2 until it lands, and its resting height 0.5 m after.
#include <cairn/cairn.hpp>

#include <cstdio>

int main() {
  cairn::World world;  // gravity (0, -9.81, 0): y is up, SI units

  cairn::BodyDef ground;
  ground.name = "ground";
  ground.type = cairn::BodyType::Static;
  ground.shapes.push_back(cairn::ShapeDesc::plane({0, 1, 0}, 0));  // the plane y = 0
  world.createBody(ground);

  cairn::BodyDef box;
  box.name = "box";
  box.mass = 1;                                                 // kg
  box.position = {0, 30, 0};                                    // m
  box.shapes.push_back(cairn::ShapeDesc::box({0.5, 0.5, 0.5}));  // half extents: a 1 m cube
  const cairn::BodyId id = world.createBody(box);

  const double h = 1.0 / 60;  // s, the fixed step
  std::printf("step %.17g\ngravity %.17g\nstart %.17g\n", h, -world.gravity().y(), box.position.y());
  for (int second = 0; second <= 5; ++second) {
    std::printf("t %d height %.17g\n", second, world.transform(id).p.y());
    for (int i = 0; i < 60; ++i) world.step(h);
  }
}
