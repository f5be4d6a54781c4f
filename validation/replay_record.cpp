// Everything the viewer knows about a running World is read here: its
// settings, gravity and time through the public face, and through the
// internals cairn's own tools reach (world/world_access.hpp) the bodies
// (pose of the center of mass, velocities, sleep, shapes relative to the
// center of mass), the contacts (points, normal, impulses) and the joints
// (frames, error, force feedback). Body i of a replay is the World's body
// slot i.
//
// Islands are derived as world/islands.cpp builds them: dynamic bodies
// linked by enabled contacts or unbroken joints, static and kinematic
// bodies never linking (a floor under two stacks keeps them apart). Each
// island is named by its lowest body index, so colours stay put from frame
// to frame while the island does.
#include "validation/replay_record.hpp"

#include "world/world_access.hpp"

#include <numeric>

namespace cairn::validation {

namespace {

void put(std::vector<float>& out, const Vec3& v) {
  out.insert(out.end(), {float(v.x()), float(v.y()), float(v.z())});
}

std::int32_t root(std::vector<std::int32_t>& parent, std::int32_t i) {
  while (parent[size_t(i)] != i) i = parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
  return i;
}

// A point given in a body's frame (from its center of mass), in the world;
// the world's own points are already world points.
Vec3 worldPoint(const detail::WorldImpl& w, BodyId id, const Vec3& local) {
  return id.isWorld() ? local : w.body(id).transform().apply(local);
}

Vec3 worldAxis(const detail::WorldImpl& w, BodyId id, const Vec3& local) {
  return id.isWorld() ? local : Vec3(w.body(id).orientation * local);
}

}  // namespace

Replay describeWorld(const World& world, Real dt) {
  Replay r;
  r.dt = dt;
  r.substeps = world.settings().substeps;
  r.gravity = world.gravity();
  const detail::WorldImpl& w = detail::internals(world);
  for (const Body& b : w.bodies())
    r.bodies.push_back(ReplayBody{b.name, b.type, b.isDynamic() ? double(b.mass) : 0.0, b.shapes, b.position, b.orientation});
  for (int j = 0; j < w.jointSlots(); ++j) {
    const JointDef& d = w.joint(JointId{j}).def;
    r.joints.push_back(ReplayJoint{d.name, d.type, d.body_a.index, d.body_b.index});
  }
  return r;
}

Replay describeScene(const SceneDesc& scene) { return describeWorld(buildWorld(scene), scene.dt); }

std::string recordRun(const SceneDesc& scene, Replay& out) {
  World world = buildWorld(scene);
  ReplayRecorder recorder(world, scene.dt, out);
  for (int s = 1; s <= scene.steps; ++s) {
    world.step(scene.dt);
    if (!world.numericalEvents().empty()) {
      const NumericalEvent& ev = world.numericalEvents().front();
      return "body '" + ev.body_name + "': non-finite state in " + ev.stage + " at step " + std::to_string(s);
    }
    recorder.record(world);
  }
  return "";
}

ReplayRecorder::ReplayRecorder(const World& world, Real dt, Replay& out) : out_(out) {
  out_ = describeWorld(world, dt);
  out_.overlays.recorded = true;
  out_.overlays.manifold_begin.push_back(0);
  out_.overlays.point_begin.push_back(0);
  record(world);
}

void ReplayRecorder::record(const World& world) {
  ReplayTrack& t = out_.cairn;
  ReplayOverlays& o = out_.overlays;
  const detail::WorldImpl& w = detail::internals(world);
  const auto& bodies = w.bodies();
  t.time.push_back(world.time());
  for (size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    put(t.position, b.position);
    t.orientation.insert(t.orientation.end(), {float(b.orientation.x()), float(b.orientation.y()),
                                               float(b.orientation.z()), float(b.orientation.w())});
    put(t.velocity, b.linear_velocity);
    put(t.angular_velocity, b.angular_velocity);
    o.asleep.push_back(b.asleep ? 1 : 0);
  }

  parent_.resize(bodies.size());
  std::iota(parent_.begin(), parent_.end(), 0);
  const auto link = [&](BodyId a, BodyId b) {
    if (a.isWorld() || b.isWorld() || !w.body(a).isDynamic() || !w.body(b).isDynamic()) return;
    const std::int32_t ra = root(parent_, a.index), rb = root(parent_, b.index);
    parent_[size_t(std::max(ra, rb))] = std::min(ra, rb);
  };
  for (const Contact& c : w.contacts()) {
    if (!c.enabled) continue;
    link(c.body_a, c.body_b);
    if (!c.touching || c.count == 0) continue;
    Vec3 friction = Vec3::Zero();
    for (int p = 0; p < c.count; ++p) {
      const ContactPointState& s = c.points[p];
      put(o.point_position, (worldPoint(w, c.body_a, s.local_a) + worldPoint(w, c.body_b, s.local_b)) / 2);
      o.point_impulse.push_back(float(s.normal_impulse));
      friction += s.friction_impulse;
    }
    put(o.manifold_normal, c.normal);
    put(o.manifold_friction, friction);
    o.manifold_body.insert(o.manifold_body.end(), {c.body_a.index, c.body_b.index});
    o.manifold_points.push_back(std::uint8_t(c.count));
  }
  o.contact_frame.push_back(std::uint32_t(o.contact_frame.size()));
  o.manifold_begin.push_back(std::uint32_t(o.manifold_points.size()));
  o.point_begin.push_back(std::uint32_t(o.point_impulse.size()));

  for (int j = 0; j < w.jointSlots(); ++j) {
    const Joint& jt = w.joint(JointId{j});
    if (jt.alive && !jt.broken) link(jt.def.body_a, jt.def.body_b);
    put(o.joint_anchor_a, worldPoint(w, jt.def.body_a, jt.local_anchor_a));
    put(o.joint_anchor_b, worldPoint(w, jt.def.body_b, jt.local_anchor_b));
    put(o.joint_axis, worldAxis(w, jt.def.body_a, jt.local_axis_a));
    const JointError e = w.jointError(JointId{j});
    o.joint_error.insert(o.joint_error.end(), {float(e.linear), float(e.angular)});
    const JointFeedback& f = w.jointFeedback(JointId{j});
    put(o.joint_force_a, f.force_a);
    put(o.joint_force_b, f.force_b);
  }
  for (size_t i = 0; i < bodies.size(); ++i)
    o.island.push_back(bodies[i].isDynamic() ? root(parent_, std::int32_t(i)) : -1);
}

}  // namespace cairn::validation
