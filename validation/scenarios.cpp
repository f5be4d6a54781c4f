#include "validation/scenarios.hpp"

#include "cairn/error.hpp"

#include <cmath>

namespace cairn::scenarios {

namespace {

BodyDef box(const std::string& name, const Vec3& p, Real mass = 1) {
  return solid(name, mass, p, ShapeDesc::box(Vec3(0.5, 0.5, 0.5)));
}

SceneDesc base(int steps) {
  SceneDesc s;
  s.dt = Real(1) / 60;
  s.steps = steps;
  return s;
}

}  // namespace

BodyDef solid(const std::string& name, Real mass, const Vec3& position, ShapeDesc shape) {
  BodyDef b;
  b.name = name;
  b.mass = mass;
  b.position = position;
  b.shapes.push_back(std::move(shape));
  return b;
}

JointDef joint(const std::string& name, JointType type, BodyId a, BodyId b, const Vec3& anchor) {
  JointDef j;
  j.name = name;
  j.type = type;
  j.body_a = a;
  j.body_b = b;
  j.anchor = anchor;
  return j;
}

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
    s.joints.push_back(joint("ball_" + std::to_string(k), JointType::Ball, k == 0 ? kWorldBody : BodyId{k - 1},
                             BodyId{k}, Vec3(Real(k), 0, 0)));
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
    s.joints.push_back(joint("ball_" + std::to_string(k), JointType::Ball, k == 0 ? kWorldBody : BodyId{k - 1},
                             BodyId{k}, Vec3(0, -Real(0.5) * k, 0)));
  }
  return s;
}

SceneDesc hingePendulum(Real amplitude) {
  SceneDesc s = base(600);
  BodyDef b = box("bob", Vec3(std::sin(amplitude), -std::cos(amplitude), 0));
  b.orientation = Quat(Eigen::AngleAxis<Real>(amplitude, Vec3::UnitZ()));
  s.bodies.push_back(b);
  JointDef j = joint("hinge", JointType::Hinge, kWorldBody, BodyId{0}, Vec3::Zero());
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

SceneDesc heavyHangingChain(int links, Real ratio) {
  SceneDesc s = hangingChain(links);
  s.bodies.back().mass = ratio;
  s.bodies.back().linear_velocity = Vec3(Real(0.05), 0, 0);
  return s;
}

SceneDesc doublingStack(int boxes) {
  SceneDesc s = base(600);
  s.bodies.push_back(ground());
  Real edge = Real(0.25), y = 0;
  for (int k = 0; k < boxes; ++k, edge *= 2) {
    BodyDef b = box("box_" + std::to_string(k), Vec3(0, y + edge / 2, 0), 1000 * edge * edge * edge);
    b.shapes[0] = ShapeDesc::box(Vec3::Constant(edge / 2));
    s.bodies.push_back(b);
    y += edge;
  }
  return s;
}

std::vector<std::string> standardNames() {
  return {"pyramid-10", "pyramid-20", "column-10", "column-20", "chain-20", "chain-100",
          "hanging-chain-20", "hinge-pendulum-0.1", "hinge-pendulum-1.5", "mass-ratio-100",
          "mass-ratio-1000", "pile-1000", "hinge-chain", "door", "ragdoll", "ramp", "restitution-drop",
          "motor-limits", "six-dof", "ragdoll-6dof"};
}

SceneDesc byName(const std::string& key) {
  const auto tail = [&](const std::string& prefix) { return key.substr(prefix.size()); };
  const auto starts = [&](const std::string& prefix) { return key.rfind(prefix, 0) == 0 && key.size() > prefix.size(); };
  try {
    if (starts("pyramid-")) return pyramid(std::stoi(tail("pyramid-")));
    if (starts("column-")) return column(std::stoi(tail("column-")));
    if (starts("heavy-chain-")) {
      const std::string t = tail("heavy-chain-");
      const auto dash = t.find('-');
      if (dash != std::string::npos) return heavyHangingChain(std::stoi(t.substr(0, dash)), std::stod(t.substr(dash + 1)));
    }
    if (starts("doubling-stack-")) return doublingStack(std::stoi(tail("doubling-stack-")));
    if (starts("hanging-chain-")) return hangingChain(std::stoi(tail("hanging-chain-")));
    if (starts("chain-")) return chain(std::stoi(tail("chain-")));
    if (starts("hinge-pendulum-")) return hingePendulum(std::stod(tail("hinge-pendulum-")));
    if (starts("mass-ratio-")) return massRatio(std::stod(tail("mass-ratio-")));
    if (starts("pile-")) {
      const int count = std::stoi(tail("pile-"));
      const int side = static_cast<int>(std::lround(std::cbrt(double(count))));
      if (count > 0 && side * side * side == count && std::to_string(count) == tail("pile-")) return pile(side);
    }
    if (key == "hinge-chain") return hingeChain(5);
    if (key == "door") return door(5);
    if (key == "ragdoll") return ragdoll(false);
    if (key == "ragdoll-6dof") return ragdoll(true);
    if (key == "motor-limits") return motorLimits();
    if (key == "six-dof") return sixDof();
    if (key == "ramp") return ramp();
    if (key == "restitution-drop") return restitutionDrop(Real(0.8));
  } catch (const std::logic_error&) {
  }
  throw InputError("scenario '" + key + "'", "", "unknown scenario");
}

}  // namespace cairn::scenarios

// ------------------------------------------------------------------------
// Scenarios beyond docs/scenarios.md's table. Each sets the table's
// common conditions itself, sleeping off included.

namespace cairn::scenarios {

namespace {

SceneDesc awake(int steps) {
  SceneDesc s;
  s.dt = Real(1) / 60;
  s.steps = steps;
  s.solver.sleeping = false;
  return s;
}

Quat aboutAxis(Real angle, const Vec3& axis) { return Quat(Eigen::AngleAxis<Real>(angle, axis.normalized())); }

BodyDef cuboid(const std::string& name, Real mass, const Vec3& p, const Vec3& half_extents) {
  return solid(name, mass, p, ShapeDesc::box(half_extents));
}

JointDef hinge(const std::string& name, BodyId a, BodyId b, const Vec3& anchor, const Vec3& axis) {
  JointDef j = joint(name, JointType::Hinge, a, b, anchor);
  j.axis = axis;
  return j;
}

}  // namespace

// Planks of 0.2 x 1 x 0.2 m (1 kg) hanging end to end from a hinge about
// the world z axis at the origin, each joined to the next by a hinge about
// z; released straight at 0.3 rad from the vertical. No collision within the
// chain. At this amplitude the motion is close to the linear normal modes,
// so two engines can be compared step by step for the whole run.
SceneDesc hingeChain(int links) {
  SceneDesc s = awake(600);
  const Real a0 = Real(0.3);
  const Vec3 down(std::sin(a0), -std::cos(a0), 0);
  for (int k = 0; k < links; ++k) {
    BodyDef b;
    b.name = "plank_" + std::to_string(k);
    b.mass = 1;
    b.position = (Real(0.5) + k) * down;
    b.orientation = aboutAxis(a0, Vec3::UnitZ());
    b.shapes.push_back(ShapeDesc::box(Vec3(0.1, 0.5, 0.1)));
    b.collision_group = 2;
    b.collision_mask = ~2u;
    s.bodies.push_back(b);
    s.joints.push_back(hinge("hinge_" + std::to_string(k), k == 0 ? kWorldBody : BodyId{k - 1}, BodyId{k},
                             Real(k) * down, Vec3::UnitZ()));
  }
  return s;
}

// A 1 x 2 x 0.05 m door of 10 kg hung from the world on a vertical hinge
// along its left edge (x = 0), with a motor (target 1 rad/s, at most
// `max_torque` N m) opening it against limits [0, pi/2]. The door is listed
// first: the hinge angle and the motor's target are its turn about +y
// relative to the world (docs/constraints.md, "Sign conventions"). Gravity is along
// the axis, so only the motor turns it: it accelerates at max_torque / I
// (I about the edge = m (w^2 + t^2) / 12 + m (w/2)^2), cruises at 1 rad/s
// and stops on the upper limit, where the motor keeps pushing.
SceneDesc door(Real max_torque) {
  SceneDesc s = awake(180);
  BodyDef d;
  d.name = "door";
  d.mass = 10;
  d.position = Vec3(0.5, 1, 0);
  d.shapes.push_back(ShapeDesc::box(Vec3(0.5, 1, 0.025)));
  s.bodies.push_back(d);
  JointDef j = hinge("hinge", BodyId{0}, kWorldBody, Vec3(0, 1, 0), Vec3::UnitY());
  j.limit.enabled = true;
  j.limit.lower = 0;
  j.limit.upper = kPi / 2;
  j.motor.enabled = true;
  j.motor.target_velocity = 1;
  j.motor.max_force = max_torque;
  s.joints.push_back(j);
  return s;
}

// An 11-part ragdoll (about 1.8 m, 56 kg): box pelvis and chest, capsule
// head and limbs. Built standing, then laid face down 1 m above the ground
// (turned a little about the vertical) and dropped. Its parts collide with
// the ground and not with each other. Every joint lists the child first,
// so its coordinates are the child's relative to its parent
// (docs/constraints.md, "Sign conventions").
//
// With `six_dof` false: cone-twist neck, shoulders and hips, hinge spine,
// elbows and knees, all limited. With `six_dof` true, the same skeleton on
// six_dof joints (translations locked), each rotation free, limited or
// locked as the body part allows: the frame's x runs along the child bone,
// the hinges' axis is the frame's z, and shoulders and hips swing up to
// 1.5 rad (86 degrees), where Euler angles would lock; the neck has a
// spring (2 Hz, damping ratio 0.5) holding the head up.
SceneDesc ragdoll(bool six_dof) {
  SceneDesc s = awake(300);
  s.bodies.push_back(ground());
  // Standing pose (feet at y = 0, facing +z), then laid down by `pose`.
  const Quat lay = aboutAxis(Real(0.3), Vec3::UnitY()) * aboutAxis(kPi / 2, Vec3::UnitX());
  const Vec3 lift(0, Real(1.1), 0);
  const auto place = [&](const Vec3& p) -> Vec3 { return lay * (p - Vec3(0, 1, 0)) + lift; };
  const Quat along_x = aboutAxis(kPi / 2, Vec3::UnitZ());  // a capsule's local y along x
  const auto part = [&](const std::string& name, Real mass, const Vec3& p, ShapeDesc shape, const Quat& q) {
    BodyDef b;
    b.name = name;
    b.mass = mass;
    b.position = place(p);
    b.orientation = lay * q;
    b.shapes.push_back(std::move(shape));
    b.collision_group = 2;
    b.collision_mask = ~2u;
    s.bodies.push_back(b);
    return BodyId{static_cast<std::int32_t>(s.bodies.size() - 1)};
  };
  const auto add = [&](JointDef j, const std::string& name, BodyId child, BodyId parent, const Vec3& anchor) {
    j.name = name;
    j.body_a = child;
    j.body_b = parent;
    j.anchor = place(anchor);
    j.axis = lay * j.axis;
    j.axis2 = lay * j.axis2;
    s.joints.push_back(j);
  };
  // A six_dof with its translations locked, frame x = bone, y = `y`.
  const auto frame = [&](const Vec3& bone, const Vec3& y) {
    JointDef j;
    j.type = JointType::SixDof;
    j.axis = bone;
    j.axis2 = y;
    for (int i = 0; i < 3; ++i) j.dofs[static_cast<size_t>(i)].mode = DofMode::Locked;
    return j;
  };
  const auto limit = [](JointDef& j, Dof axis, Real lower, Real upper) {
    DofDef& d = j.dofs[static_cast<size_t>(axis)];
    d.mode = lower == upper ? DofMode::Locked : DofMode::Limited;
    if (d.mode == DofMode::Limited) d.limit = LimitDef{true, lower, upper, 0, {}};
  };
  // Cone-twist about the bone: twist within +-twist, swing spans s1 (toward
  // y) and s2; as six_dof, swing y in [y_lo, y_hi], swing z in [z_lo, z_hi].
  struct Swing {
    Real twist, y_lo, y_hi, z_lo, z_hi;
  };
  const auto cone = [&](const std::string& name, BodyId child, BodyId parent, const Vec3& anchor, const Vec3& bone,
                        const Vec3& y, Real span1, Real span2, const Swing& range) {
    if (six_dof) {
      JointDef j = frame(bone, y);
      limit(j, Dof::RotationX, -range.twist, range.twist);
      limit(j, Dof::RotationY, range.y_lo, range.y_hi);
      limit(j, Dof::RotationZ, range.z_lo, range.z_hi);
      add(j, name, child, parent, anchor);
      return;
    }
    JointDef j;
    j.type = JointType::ConeTwist;
    j.axis = bone;
    j.swing_span1 = span1;
    j.swing_span2 = span2;
    j.limit = LimitDef{true, -range.twist, range.twist, 0, {}};
    add(j, name, child, parent, anchor);
  };
  // A hinge about `axis` bending the child bone by [lower, upper]; as
  // six_dof, rotation z (= axis) limited and the others locked.
  const auto knuckle = [&](const std::string& name, BodyId child, BodyId parent, const Vec3& anchor, const Vec3& bone,
                           const Vec3& axis, Real lower, Real upper) {
    if (six_dof) {
      JointDef j = frame(bone, axis.cross(bone));
      limit(j, Dof::RotationX, 0, 0);
      limit(j, Dof::RotationY, 0, 0);
      limit(j, Dof::RotationZ, lower, upper);
      add(j, name, child, parent, anchor);
      return;
    }
    JointDef j = hinge(name, child, parent, Vec3::Zero(), axis);
    j.limit = LimitDef{true, lower, upper, 0, {}};
    add(j, name, child, parent, anchor);
  };

  const BodyId pelvis = part("pelvis", 8, Vec3(0, 1.0, 0), ShapeDesc::box(Vec3(0.15, 0.1, 0.1)), Quat::Identity());
  const BodyId chest = part("chest", 15, Vec3(0, 1.31, 0), ShapeDesc::box(Vec3(0.18, 0.2, 0.1)), Quat::Identity());
  const BodyId head = part("head", 4, Vec3(0, 1.66, 0), ShapeDesc::capsule(0.1, 0.05), Quat::Identity());
  if (six_dof) {
    // The spine also twists and bends sideways a little.
    JointDef spine = frame(Vec3::UnitY(), Vec3::UnitZ());  // z = x: the forward bend
    limit(spine, Dof::RotationX, -0.3, 0.3);
    limit(spine, Dof::RotationY, -0.2, 0.2);
    limit(spine, Dof::RotationZ, -0.3, 0.6);
    add(spine, "spine", chest, pelvis, Vec3(0, 1.1, 0));
    // The neck nods (rotation y about x) and tilts on a spring that holds
    // the head up.
    JointDef neck = frame(Vec3::UnitY(), Vec3::UnitX());
    limit(neck, Dof::RotationX, -0.6, 0.6);
    limit(neck, Dof::RotationY, -0.4, 0.6);
    limit(neck, Dof::RotationZ, -0.4, 0.4);
    for (const Dof d : {Dof::RotationY, Dof::RotationZ}) {
      DofSpringDef& sp = neck.dofs[static_cast<size_t>(d)].spring;
      sp.enabled = true;
      sp.softness.frequency = 2;
      sp.softness.damping_ratio = 0.5;
    }
    add(neck, "neck", head, chest, Vec3(0, 1.51, 0));
  } else {
    knuckle("spine", chest, pelvis, Vec3(0, 1.1, 0), Vec3::UnitY(), Vec3::UnitX(), Real(-0.3), Real(0.6));
    cone("neck", head, chest, Vec3(0, 1.51, 0), Vec3::UnitY(), Vec3::UnitX(), Real(0.5), Real(0.5),
         Swing{0.6, 0, 0, 0, 0});
  }
  for (int side : {-1, 1}) {
    const std::string lr = side < 0 ? "left" : "right";
    const Real sx = Real(side);
    const BodyId upper_arm =
        part(lr + "_upper_arm", 2, Vec3(sx * 0.37, 1.45, 0), ShapeDesc::capsule(0.05, 0.1), along_x);
    const BodyId forearm = part(lr + "_forearm", 1.5, Vec3(sx * 0.67, 1.45, 0), ShapeDesc::capsule(0.045, 0.1), along_x);
    const BodyId thigh = part(lr + "_thigh", 7, Vec3(sx * 0.09, 0.7, 0), ShapeDesc::capsule(0.07, 0.13), Quat::Identity());
    const BodyId shin = part(lr + "_shin", 4, Vec3(sx * 0.09, 0.25, 0), ShapeDesc::capsule(0.055, 0.15), Quat::Identity());
    // Shoulder: y up, so swing z (about +-z) raises the arm on both sides,
    // up to 1.5 rad.
    cone(lr + "_shoulder", upper_arm, chest, Vec3(sx * 0.2, 1.45, 0), Vec3(sx, 0, 0), Vec3::UnitY(), Real(1.2),
         Real(1.2), Swing{0.5, -1.2, 1.2, -0.6, 1.5});
    knuckle(lr + "_elbow", forearm, upper_arm, Vec3(sx * 0.52, 1.45, 0), Vec3(sx, 0, 0), Vec3(0, -sx, 0), Real(0),
            Real(2.3));
    // Hip: y along +x, so swing y (about x) swings the leg forward for
    // negative angles, up to 1.5 rad, and back 0.4 rad.
    cone(lr + "_hip", thigh, pelvis, Vec3(sx * 0.09, 0.9, 0), Vec3(0, -1, 0), Vec3::UnitX(), Real(0.8), Real(0.5),
         Swing{0.3, -1.5, 0.4, -0.5, 0.5});
    knuckle(lr + "_knee", shin, thigh, Vec3(sx * 0.09, 0.48, 0), Vec3(0, -1, 0), Vec3::UnitX(), Real(0), Real(2.2));
  }
  return s;
}

// Two motors driving into asymmetric limits, each body listed first so that
// the targets and limits are its own motion (docs/constraints.md, "Sign
// conventions"). Gravity is along the hinge axis and across the rail.
//   arm   a 1 x 0.1 x 0.1 m bar of 2 kg on a vertical hinge at its end
//         (x = 0), limits [-0.4, 1.1] rad, motor +1.5 rad/s with at most
//         2 N m: it accelerates at 2 / I (I = m (L^2 + t^2) / 12 + m (L/2)^2
//         = 0.6683 kg m^2), turns at 1.5 rad/s and stops on +1.1 rad;
//   cart  a 0.4 m cube of 1 kg on a slider along x at z = 2, limits
//         [-0.3, 0.6] m, motor -0.4 m/s with at most 1 N: it accelerates at
//         1 m/s^2, slides at 0.4 m/s and stops on -0.3 m.
SceneDesc motorLimits() {
  SceneDesc s = awake(120);
  s.bodies.push_back(cuboid("arm", 2, Vec3(0.5, 1, 0), Vec3(0.5, 0.05, 0.05)));
  s.bodies.push_back(cuboid("cart", 1, Vec3(0, 1, 2), Vec3(0.2, 0.2, 0.2)));
  JointDef h = hinge("hinge", BodyId{0}, kWorldBody, Vec3(0, 1, 0), Vec3::UnitY());
  h.limit = LimitDef{true, -0.4, 1.1, 0, {}};
  h.motor.enabled = true;
  h.motor.target_velocity = 1.5;
  h.motor.max_force = 2;
  s.joints.push_back(h);
  JointDef r = hinge("rail", BodyId{1}, kWorldBody, Vec3(0, 1, 2), Vec3::UnitX());
  r.type = JointType::Slider;
  r.limit = LimitDef{true, -0.3, 0.6, 0, {}};
  r.motor.enabled = true;
  r.motor.target_velocity = -0.4;
  r.motor.max_force = 1;
  s.joints.push_back(r);
  return s;
}

// A 0.4 m cube of 2 kg held at its center by a six_dof to the world (the
// cube listed first; frame = the world's axes), one axis of each kind:
//   translation x  free; the cube starts at 0.3 m/s along x
//   translation y  limited to [-0.25, 0.1]: it falls onto -0.25
//   translation z  locked
//   rotation x     velocity motor, 1 rad/s with at most 0.5 N m (twist)
//   rotation y     spring k = 0.2 N m/rad, c = 0.02 N m s/rad about 0
//                  (0.31 Hz, damping ratio 0.1 for I = 0.0533 kg m^2); the
//                  cube starts turning at 0.3 rad/s about y
//   rotation z     limited to [-0.15, 0.3]: the cube starts turning at
//                  0.5 rad/s about z and stops on 0.3
// The cube's inertia is isotropic, so spinning adds no gyroscopic torque,
// and with the anchor at its center every axis moves on its own.
SceneDesc sixDof() {
  SceneDesc s = awake(180);
  BodyDef cube = cuboid("cube", 2, Vec3::Zero(), Vec3(0.2, 0.2, 0.2));
  cube.linear_velocity = Vec3(0.3, 0, 0);
  cube.angular_velocity = Vec3(0, 0.3, 0.5);
  s.bodies.push_back(cube);
  JointDef j;
  j.name = "six_dof";
  j.type = JointType::SixDof;
  j.body_a = BodyId{0};
  j.body_b = kWorldBody;
  j.axis = Vec3::UnitX();
  j.axis2 = Vec3::UnitY();
  DofDef* d = j.dofs.data();
  d[1].mode = DofMode::Limited;
  d[1].limit = LimitDef{true, -0.25, 0.1, 0, {}};
  d[2].mode = DofMode::Locked;
  d[3].motor.enabled = true;
  d[3].motor.target_velocity = 1;
  d[3].motor.max_force = 0.5;
  d[4].spring.enabled = true;
  d[4].spring.softness.stiffness = 0.2;
  d[4].spring.softness.damping = 0.02;
  d[5].mode = DofMode::Limited;
  d[5].limit = LimitDef{true, -0.15, 0.3, 0, {}};
  s.joints.push_back(j);
  return s;
}

// Two static ramps of 12 x 0.5 x 2 m, at 20 degrees (z = -3) and at 35
// degrees (z = +3), each descending toward +x, with a 1 m cube of 1 kg
// resting on it 4 m up the slope; friction 0.5 on both (combined 0.5).
// tan 20 = 0.36 < 0.5: the first box sticks. tan 35 = 0.70 > 0.5: the second
// slides with a = g (sin 35 - 0.5 cos 35) = 1.609 m/s^2.
SceneDesc ramp() {
  SceneDesc s = awake(180);
  const Real degrees[2] = {20, 35};
  for (int k = 0; k < 2; ++k) {
    const Real theta = degrees[k] * kPi / 180;
    const Quat q = aboutAxis(-theta, Vec3::UnitZ());
    const Vec3 normal = q * Vec3::UnitY(), downhill = q * Vec3::UnitX();
    const Vec3 centre(0, 4, k == 0 ? -3 : 3);
    const std::string tag = std::to_string(static_cast<int>(degrees[k]));
    BodyDef r;
    r.name = "ramp_" + tag;
    r.type = BodyType::Static;
    r.position = centre;
    r.orientation = q;
    r.friction = Real(0.5);
    r.shapes.push_back(ShapeDesc::box(Vec3(6, 0.25, 1)));
    s.bodies.push_back(r);
    BodyDef b = box("box_" + tag, centre + Real(0.75) * normal - Real(4) * downhill);
    b.orientation = q;
    s.bodies.push_back(b);
  }
  return s;
}

// A sphere of radius 0.25 m and 1 kg with restitution e, its bottom 2 m
// above the ground (restitution 0; cairn combines by the maximum). The
// first bounce rises to e^2 x 2 m (1.28 m for e = 0.8).
SceneDesc restitutionDrop(Real restitution) {
  SceneDesc s = awake(180);
  s.bodies.push_back(ground());
  BodyDef b;
  b.name = "ball";
  b.mass = 1;
  b.position = Vec3(0, 2.25, 0);
  b.restitution = restitution;
  b.shapes.push_back(ShapeDesc::sphere(0.25));
  s.bodies.push_back(b);
  return s;
}

SceneDesc sideBySide(const SceneDesc& one, int copies, const Vec3& offset) {
  if (!one.springs.empty()) throw InputError("sideBySide", "springs", "copies scenes of bodies and joints only");
  SceneDesc s = one;
  s.bodies.clear();
  s.joints.clear();
  s.validation_json.clear();  // its checks name the bodies of one copy
  std::vector<std::int32_t> static_index(one.bodies.size(), -1);
  for (int c = 0; c < copies; ++c) {
    std::vector<std::int32_t> index(one.bodies.size());
    for (size_t i = 0; i < one.bodies.size(); ++i) {
      BodyDef b = one.bodies[i];
      if (b.type == BodyType::Static && static_index[i] >= 0) {
        index[i] = static_index[i];
        continue;
      }
      index[i] = static_cast<std::int32_t>(s.bodies.size());
      if (b.type == BodyType::Static) static_index[i] = index[i];
      else b.position += offset * Real(c);
      b.name += "_" + std::to_string(c);
      s.bodies.push_back(b);
    }
    for (JointDef j : one.joints) {
      if (!j.body_a.isWorld()) j.body_a = BodyId{index[static_cast<size_t>(j.body_a.index)]};
      if (!j.body_b.isWorld()) j.body_b = BodyId{index[static_cast<size_t>(j.body_b.index)]};
      j.anchor += offset * Real(c);
      j.anchor_a += offset * Real(c);
      j.anchor_b += offset * Real(c);
      j.name += "_" + std::to_string(c);
      s.joints.push_back(j);
    }
  }
  return s;
}

}  // namespace cairn::scenarios
