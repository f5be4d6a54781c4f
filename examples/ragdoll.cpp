// A ragdoll: eleven bodies (boxes and capsules) held by hinges (knees,
// elbows, spine) and cone-twist joints (hips, shoulders, neck) with limits,
// thrown upwards with a spin and left to fall onto the ground.
//
// Figures a test checks (tests/examples/):
//  - in flight, joints push the parts on each other but not the whole: the
//    total momentum changes by exactly M g t, and the centre of mass
//    follows the discrete free fall of the engine's semi-implicit Euler,
//    y_n = y0 + n h vy0 + h^2 g n (n + 1) / 2;
//  - at rest on the ground the contacts carry the whole weight M g, the
//    joints hold (anchor separation) and nothing sinks into the ground.
#include <cairn/cairn.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

struct Ragdoll {
  cairn::World& world;
  std::vector<cairn::BodyId> parts;
  std::vector<cairn::JointId> joints;
  cairn::Vec3 v0, w0, c0;  // the throw: v0 + w0 x (x - c0) at each point

  cairn::BodyId part(const std::string& name, double mass, const cairn::Vec3& at, const cairn::ShapeDesc& shape) {
    cairn::BodyDef d;
    d.name = name;
    d.mass = mass;
    d.position = at;
    d.linear_velocity = v0 + w0.cross(at - c0);
    d.angular_velocity = w0;
    d.shapes.push_back(shape);
    parts.push_back(world.createBody(d));
    return parts.back();
  }
  void hinge(const std::string& name, cairn::BodyId a, cairn::BodyId b, const cairn::Vec3& at, double lo, double hi) {
    cairn::JointDef j;
    j.name = name;
    j.type = cairn::JointType::Hinge;
    j.body_a = a;
    j.body_b = b;
    j.anchor = at;
    j.axis = cairn::Vec3::UnitX();
    j.limit = {true, lo, hi, 0, {}};
    joints.push_back(world.createJoint(j));
  }
  void coneTwist(const std::string& name, cairn::BodyId a, cairn::BodyId b, const cairn::Vec3& at,
                 const cairn::Vec3& axis, double swing1, double swing2, double twist) {
    cairn::JointDef j;
    j.name = name;
    j.type = cairn::JointType::ConeTwist;
    j.body_a = a;
    j.body_b = b;
    j.anchor = at;
    j.axis = axis;
    j.swing_span1 = swing1;
    j.swing_span2 = swing2;
    j.limit = {true, -twist, twist, 0, {}};
    joints.push_back(world.createJoint(j));
  }
};

}  // namespace

int main() {
  cairn::WorldDef def;
  def.settings.sleeping = false;  // the test reads the contacts at rest
  cairn::World world(def);
  cairn::BodyDef ground;
  ground.name = "ground";
  ground.type = cairn::BodyType::Static;
  ground.shapes.push_back(cairn::ShapeDesc::plane({0, 1, 0}, 0));
  const cairn::BodyId ground_id = world.createBody(ground);

  using cairn::ShapeDesc;
  using cairn::Vec3;
  const double H = 2;  // feet 2 m above the ground
  Ragdoll r{world, {}, {}, Vec3(1.5, 2, 0.5), Vec3(0, 0, 2), Vec3(0, H + 1, 0)};
  const auto capsule = [](double radius, double half) { return ShapeDesc::capsule(radius, half); };
  const cairn::BodyId pelvis = r.part("pelvis", 8, {0, H + 0.91, 0}, ShapeDesc::box({0.15, 0.1, 0.1}));
  const cairn::BodyId chest = r.part("chest", 15, {0, H + 1.21, 0}, ShapeDesc::box({0.18, 0.2, 0.1}));
  const cairn::BodyId head = r.part("head", 4, {0, H + 1.56, 0}, capsule(0.1, 0.05));
  r.hinge("spine", pelvis, chest, {0, H + 1.01, 0}, -0.3, 0.6);
  r.coneTwist("neck", chest, head, {0, H + 1.41, 0}, Vec3::UnitY(), 0.5, 0.5, 0.6);
  for (const double side : {-1.0, 1.0}) {
    const std::string s = side < 0 ? "right_" : "left_";
    const cairn::BodyId thigh = r.part(s + "thigh", 7, {0.1 * side, H + 0.61, 0}, capsule(0.07, 0.13));
    const cairn::BodyId shin = r.part(s + "shin", 4, {0.1 * side, H + 0.205, 0}, capsule(0.055, 0.15));
    const cairn::BodyId upper = r.part(s + "upper_arm", 2, {0.25 * side, H + 1.23, 0}, capsule(0.05, 0.1));
    const cairn::BodyId fore = r.part(s + "forearm", 1.5, {0.25 * side, H + 0.935, 0}, capsule(0.045, 0.1));
    r.coneTwist(s + "hip", pelvis, thigh, {0.1 * side, H + 0.81, 0}, -Vec3::UnitY(), 0.8, 0.5, 0.3);
    r.hinge(s + "knee", thigh, shin, {0.1 * side, H + 0.41, 0}, 0, 2.2);
    r.coneTwist(s + "shoulder", chest, upper, {0.25 * side, H + 1.38, 0}, -Vec3::UnitY(), 1.2, 1.2, 0.5);
    r.hinge(s + "elbow", upper, fore, {0.25 * side, H + 1.08, 0}, 0, 2.3);
  }

  const auto total = [&](auto per_body) {
    Vec3 sum = Vec3::Zero();
    for (const cairn::BodyId id : r.parts) sum += per_body(id);
    return sum;
  };
  double mass = 0;
  for (const cairn::BodyId id : r.parts) mass += world.mass(id);
  const auto momentum = [&] { return total([&](cairn::BodyId id) { return Vec3(world.mass(id) * world.linearVelocity(id)); }); };
  const auto com = [&] { return Vec3(total([&](cairn::BodyId id) { return Vec3(world.mass(id) * world.centerOfMass(id)); }) / mass); };

  const double h = 1.0 / 60;
  const Vec3 p0 = momentum(), x0 = com();
  std::printf("mass %.17g\nstep %.17g\ngravity %.17g\n", mass, h, -world.gravity().y());
  std::printf("com0 %.17g %.17g %.17g\nmomentum0 %.17g %.17g %.17g\n", x0.x(), x0.y(), x0.z(), p0.x(), p0.y(), p0.z());
  int first_contact = -1;
  for (int n = 1; n <= 480; ++n) {
    world.step(h);
    if (first_contact < 0 && !world.contacts().empty()) {
      first_contact = n;
      std::printf("first_contact_step %d\n", n);
    }
    if (first_contact < 0 && n % 6 == 0) {
      const Vec3 p = momentum(), x = com();
      std::printf("flight n %d com %.17g %.17g %.17g momentum %.17g %.17g %.17g\n", n, x.x(), x.y(), x.z(), p.x(), p.y(),
                  p.z());
    }
  }
  // At rest: the ground's support, the joints' separation, the penetration.
  double support = 0, max_depth = 0, joint_error = 0;
  for (const cairn::ContactData& c : world.contacts(ground_id))
    for (int i = 0; i < c.count; ++i) {
      support += std::abs(c.normal.y()) * c.normal_impulses[i] / h;
      max_depth = std::max(max_depth, c.depths[i]);
    }
  for (const cairn::JointId j : r.joints) joint_error = std::max(joint_error, world.jointError(j).linear);
  double kinetic = world.kineticEnergy();
  std::printf("rest_support %.17g\nrest_kinetic %.17g\nrest_joint_error %.17g\nrest_depth %.17g\n", support, kinetic,
              joint_error, max_depth);
}
