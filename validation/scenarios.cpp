#include "validation/scenarios.hpp"

#include "dynamics/error.hpp"

#include <cmath>

namespace cairn::scenarios {

namespace {

BodyDef box(const std::string& name, const Vec3& p, Real mass = 1) {
  BodyDef d;
  d.name = name;
  d.mass = mass;
  d.position = p;
  d.friction = Real(0.5);
  d.shapes.push_back(ShapeDesc::box(Vec3(0.5, 0.5, 0.5)));
  return d;
}

SceneDesc base(int steps) {
  SceneDesc s;
  s.dt = Real(1) / 60;
  s.steps = steps;
  return s;
}

}  // namespace

BodyDef ground() {
  BodyDef g;
  g.name = "ground";
  g.type = BodyType::Static;
  g.position = Vec3(0, -0.5, 0);
  g.friction = Real(0.5);
  g.shapes.push_back(ShapeDesc::box(Vec3(100, 0.5, 100)));
  return g;
}

SceneDesc pyramid(int n) {
  SceneDesc s = base(600);
  s.bodies.push_back(ground());
  for (int row = 0; row < n; ++row) {
    const int count = n - row;
    const Real x0 = -Real(1.01) * (count - 1) / 2;
    for (int i = 0; i < count; ++i)
      s.bodies.push_back(box("box_" + std::to_string(row) + "_" + std::to_string(i),
                             Vec3(x0 + Real(1.01) * i, Real(0.5) + row, 0)));
  }
  return s;
}

SceneDesc column(int n) {
  SceneDesc s = base(600);
  s.bodies.push_back(ground());
  for (int k = 0; k < n; ++k) s.bodies.push_back(box("box_" + std::to_string(k), Vec3(0, Real(0.5) + k, 0)));
  return s;
}

SceneDesc chain(int n) {
  SceneDesc s = base(600);
  for (int k = 0; k < n; ++k) {
    BodyDef b;
    b.name = "link_" + std::to_string(k);
    b.mass = 1;
    b.position = Vec3(Real(0.5) + k, 0, 0);
    b.shapes.push_back(ShapeDesc::sphere(Real(0.1)));
    b.collision_group = 2;  // no collision within the chain
    b.collision_mask = ~2u;
    s.bodies.push_back(b);
    JointDef j;
    j.name = "ball_" + std::to_string(k);
    j.type = JointType::Ball;
    j.body_a = k == 0 ? kWorldBody : BodyId{k - 1};
    j.body_b = BodyId{k};
    j.anchor = Vec3(Real(k), 0, 0);
    s.joints.push_back(j);
  }
  return s;
}

SceneDesc hangingChain(int n) {
  SceneDesc s = base(600);
  for (int k = 0; k < n; ++k) {
    BodyDef b;
    b.name = "link_" + std::to_string(k);
    b.mass = 1;
    b.position = Vec3(0, -Real(0.25) - Real(0.5) * k, 0);
    b.linear_velocity = k == n - 1 ? Vec3(0.5, 0, 0) : Vec3::Zero();  // the nudge
    b.shapes.push_back(ShapeDesc::box(Vec3(0.05, 0.25, 0.05)));
    b.collision_group = 2;
    b.collision_mask = ~2u;
    s.bodies.push_back(b);
    JointDef j;
    j.name = "ball_" + std::to_string(k);
    j.type = JointType::Ball;
    j.body_a = k == 0 ? kWorldBody : BodyId{k - 1};
    j.body_b = BodyId{k};
    j.anchor = Vec3(0, -Real(0.5) * k, 0);
    s.joints.push_back(j);
  }
  return s;
}

SceneDesc hingePendulum(Real amplitude) {
  SceneDesc s = base(600);
  BodyDef b = box("bob", Vec3(std::sin(amplitude), -std::cos(amplitude), 0));
  b.orientation = Quat(Eigen::AngleAxis<Real>(amplitude, Vec3::UnitZ()));
  s.bodies.push_back(b);
  JointDef j;
  j.name = "hinge";
  j.type = JointType::Hinge;
  j.body_a = kWorldBody;
  j.body_b = BodyId{0};
  j.anchor = Vec3::Zero();
  j.axis = Vec3::UnitZ();
  s.joints.push_back(j);
  return s;
}

SceneDesc massRatio(Real ratio) {
  SceneDesc s = base(600);
  s.bodies.push_back(ground());
  s.bodies.push_back(box("light", Vec3(0, 0.5, 0), 1));
  s.bodies.push_back(box("heavy", Vec3(0, 1.5, 0), ratio));
  return s;
}

SceneDesc pile(int per_side) {
  SceneDesc s = base(600);
  s.bodies.push_back(ground());
  const Real off = Real(1.2) * (per_side - 1) / 2;
  for (int y = 0; y < per_side; ++y)
    for (int z = 0; z < per_side; ++z)
      for (int x = 0; x < per_side; ++x)
        s.bodies.push_back(box("box_" + std::to_string(x) + "_" + std::to_string(y) + "_" + std::to_string(z),
                               Vec3(Real(1.2) * x - off, 1 + Real(1.2) * y, Real(1.2) * z - off)));
  return s;
}

std::vector<std::string> standardNames() {
  return {"pyramid-10", "pyramid-20", "column-10", "column-20", "chain-20", "chain-100",
          "hanging-chain-20", "hinge-pendulum-0.1", "hinge-pendulum-1.5", "mass-ratio-100",
          "mass-ratio-1000", "pile-1000"};
}

SceneDesc byName(const std::string& key) {
  const auto tail = [&](const std::string& prefix) { return key.substr(prefix.size()); };
  const auto starts = [&](const std::string& prefix) { return key.rfind(prefix, 0) == 0 && key.size() > prefix.size(); };
  try {
    if (starts("pyramid-")) return pyramid(std::stoi(tail("pyramid-")));
    if (starts("column-")) return column(std::stoi(tail("column-")));
    if (starts("hanging-chain-")) return hangingChain(std::stoi(tail("hanging-chain-")));
    if (starts("chain-")) return chain(std::stoi(tail("chain-")));
    if (starts("hinge-pendulum-")) return hingePendulum(std::stod(tail("hinge-pendulum-")));
    if (starts("mass-ratio-")) return massRatio(std::stod(tail("mass-ratio-")));
    if (key == "pile-1000") return pile(10);
  } catch (const std::logic_error&) {
  }
  throw InputError("scenario '" + key + "'", "", "unknown scenario");
}

}  // namespace cairn::scenarios
