// Built against an installed cairn by tests/install/install_test.sh: one
// sphere dropped for one second must match the discrete free fall of the
// engine's semi-implicit Euler, y = y0 - g h^2 n (n + 1) / 2, to round-off
// (1e-9 m), and a bad definition must throw InputError. Exit 0 when both hold.
#include <cairn/cairn.hpp>

#include <cmath>
#include <cstdio>

int main() {
  cairn::World world;
  cairn::BodyDef ball;
  ball.name = "ball";
  ball.mass = 1;
  ball.position = {0, 10, 0};
  ball.shapes.push_back(cairn::ShapeDesc::sphere(0.5));
  const cairn::BodyId id = world.createBody(ball);
  cairn::FixedStepDriver driver(world, {1.0 / 60, 8});
  for (int i = 0; i < 60; ++i) driver.advance(1.0 / 60);
  const double h = 1.0 / 60, g = 9.81, n = 60;
  const double expected = 10 - g * h * h * n * (n + 1) / 2;
  const double y = world.transform(id).p.y();
  std::printf("y %.17g expected %.17g\n", y, expected);
  bool threw = false;
  try {
    cairn::BodyDef bad = ball;
    bad.mass = -1;
    world.createBody(bad);
  } catch (const cairn::InputError& e) {
    threw = true;
    std::printf("InputError: %s\n", e.what());
  }
  return std::abs(y - expected) < 1e-9 && threw ? 0 : 1;
}
