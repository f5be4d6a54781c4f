// Running cairn and Bullet side by side and measuring both with the same
// code (compare.hpp): Bullet's states are copied into a shadow cairn World
// after every step and measured there.
#include "collision/manifold.hpp"
#include "cairn/error.hpp"
#include "validation/bullet_oracle.hpp"
#include "validation/compare.hpp"
#include "validation/replay_bullet.hpp"
#include "validation/replay_record.hpp"
#include "world/world_access.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace cairn::validation {

namespace {

std::uint64_t pairKey(int a, int b) {
  const auto lo = static_cast<std::uint64_t>(std::min(a, b)), hi = static_cast<std::uint64_t>(std::max(a, b));
  return lo << 32 | hi;
}

// Radius of a sphere about the shape's origin that holds it; infinite for
// planes and meshes (tested against everything).
Real boundingRadius(const ShapeDesc& s) {
  switch (s.type) {
    case ShapeType::Sphere: return s.radius;
    case ShapeType::Box: return s.half_extents.norm();
    case ShapeType::Capsule: return s.radius + s.half_height;
    case ShapeType::Cylinder: return std::hypot(s.radius, s.half_height);
    case ShapeType::ConvexHull: {
      Real r = 0;
      if (s.hull)
        for (const Vec3& v : s.hull->vertices) r = std::max(r, v.norm());
      return r;
    }
    case ShapeType::Plane:
    case ShapeType::Mesh: return kInf;
  }
  return kInf;
}

bool mayCollide(const Body& a, const Body& b) {
  if (!a.isDynamic() && !b.isDynamic()) return false;
  return (a.collision_group & b.collision_mask) != 0 && (b.collision_group & a.collision_mask) != 0;
}

struct ShapeEntry {
  int body, shape;
  Transform pose;
  Real radius;
  Real lo;  // pose.p.x - radius
};

}  // namespace

double geometricPenetration(const World& world, const std::vector<std::uint64_t>& joined) {
  std::vector<ShapeEntry> finite, infinite;
  const auto& bodies = cairn::detail::internals(world).bodies();
  for (size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    for (size_t k = 0; k < b.shapes.size(); ++k) {
      const ShapeDesc& s = b.shapes[k];
      ShapeEntry e{static_cast<int>(i), static_cast<int>(k), b.transform() * s.local, boundingRadius(s), 0};
      e.lo = e.pose.p.x() - e.radius;
      (std::isfinite(e.radius) ? finite : infinite).push_back(e);
    }
  }
  std::sort(finite.begin(), finite.end(), [](const ShapeEntry& a, const ShapeEntry& b) { return a.lo < b.lo; });
  std::vector<Manifold> manifolds;
  double deepest = 0;
  const auto test = [&](const ShapeEntry& a, const ShapeEntry& b) {
    if (a.body == b.body) return;
    const Body& ba = bodies[size_t(a.body)];
    const Body& bb = bodies[size_t(b.body)];
    if (!mayCollide(ba, bb)) return;
    const ShapeDesc& sa = ba.shapes[size_t(a.shape)];
    const ShapeDesc& sb = bb.shapes[size_t(b.shape)];
    if (!canCollide(sa.type, sb.type)) return;
    if (std::binary_search(joined.begin(), joined.end(), pairKey(a.body, b.body))) return;
    manifolds.clear();
    collide(sa, a.pose, sb, b.pose, 0, manifolds);
    for (const Manifold& m : manifolds)
      for (int p = 0; p < m.count; ++p) deepest = std::max(deepest, double(m.points[p].depth));
  };
  for (size_t i = 0; i < finite.size(); ++i) {
    const Real hi = finite[i].pose.p.x() + finite[i].radius;
    for (size_t j = i + 1; j < finite.size() && finite[j].lo <= hi; ++j) {
      if ((finite[i].pose.p - finite[j].pose.p).norm() > finite[i].radius + finite[j].radius) continue;
      test(finite[i], finite[j]);
    }
    for (const ShapeEntry& inf : infinite) test(inf, finite[i]);
  }
  return deepest;
}

// ---------------------------------------------------------------- Recorder

Recorder::Recorder(const SceneDesc& scene, const ValidationSpec& spec) : spec_(spec) {
  for (const TraceSpec& t : spec.traces) trace_body_.push_back(scene.bodyIndex(t.body));
  for (const JointDef& j : scene.joints)
    if (!j.collide_connected && !j.body_a.isWorld() && !j.body_b.isWorld())
      joined_.push_back(pairKey(j.body_a.index, j.body_b.index));
  std::sort(joined_.begin(), joined_.end());
  // Penetration is measured when two bodies could ever touch: a dynamic
  // body with a shape and any other body with a shape that it may collide
  // with (and is not joined to).
  for (size_t i = 0; i < scene.bodies.size() && !contacts_possible_; ++i)
    for (size_t k = 0; k < scene.bodies.size() && !contacts_possible_; ++k) {
      const BodyDef& a = scene.bodies[i];
      const BodyDef& b = scene.bodies[k];
      if (i == k || a.type != BodyType::Dynamic || a.shapes.empty() || b.shapes.empty()) continue;
      if ((a.collision_group & b.collision_mask) == 0 || (b.collision_group & a.collision_mask) == 0) continue;
      if (std::binary_search(joined_.begin(), joined_.end(), pairKey(int(i), int(k)))) continue;
      contacts_possible_ = true;
    }
}

void Recorder::record(const World& world, double time, double step_seconds, EngineRun& run) {
  const auto& bodies = cairn::detail::internals(world).bodies();
  if (!started_) {
    for (const Body& b : bodies) {
      start_position_.push_back(b.position);
      start_orientation_.push_back(b.orientation);
    }
    run.traces.assign(spec_.traces.size(), {});
    started_ = true;
  }
  run.time.push_back(time);
  run.step_seconds.push_back(step_seconds);
  std::vector<Vec3> x, v;
  std::vector<Quat> q;
  x.reserve(bodies.size());
  v.reserve(bodies.size());
  q.reserve(bodies.size());
  double rot = 0;
  for (const Body& b : bodies) {
    x.push_back(b.position);
    q.push_back(b.orientation);
    v.push_back(b.linear_velocity);
    if (b.isDynamic()) rot += 0.5 * b.angular_velocity.dot(b.angularMomentum());
  }
  run.positions.push_back(std::move(x));
  run.orientations.push_back(std::move(q));
  run.velocities.push_back(std::move(v));
  run.rotational_energy.push_back(rot);
  run.energy.push_back(world.kineticEnergy() + world.potentialEnergy());
  run.momentum.push_back(world.linearMomentum());
  double jl = 0, ja = 0;
  for (int j = 0; j < cairn::detail::internals(world).jointSlots(); ++j) {
    const JointError e = world.jointError(JointId{j});
    jl = std::max(jl, double(e.linear));
    ja = std::max(ja, double(e.angular));
  }
  run.joint_error.push_back(jl);
  run.joint_error_angular.push_back(ja);
  if (contacts_possible_) run.penetration.push_back(geometricPenetration(world, joined_));
  if (!cairn::detail::internals(world).springs().empty()) {
    const Spring& s = cairn::detail::internals(world).springs().front();
    const Vec3 pa = s.def.body_a.isWorld() ? s.local_a : cairn::detail::internals(world).body(s.def.body_a).transform().apply(s.local_a);
    const Vec3 pb = s.def.body_b.isWorld() ? s.local_b : cairn::detail::internals(world).body(s.def.body_b).transform().apply(s.local_b);
    run.spring_length.push_back((pb - pa).norm());
  }
  for (size_t t = 0; t < spec_.traces.size(); ++t) {
    const TraceSpec& ts = spec_.traces[t];
    const int i = trace_body_[t];
    double value = std::numeric_limits<double>::quiet_NaN();
    if (i >= 0) {
      const Body& b = bodies[size_t(i)];
      if (ts.quantity == "height") value = b.position.y();
      else if (ts.quantity == "x") value = b.position.x();
      else if (ts.quantity == "z") value = b.position.z();
      else if (ts.quantity == "swing_angle") {
        const Vec3 d = b.position - ts.pivot;
        value = std::atan2(d.x(), -d.y());
      } else if (ts.quantity == "angle") {
        value = rotationVectorFromQuat(b.orientation * start_orientation_[size_t(i)].conjugate()).dot(ts.axis);
      } else if (ts.quantity == "slope") {
        value = (b.position - start_position_[size_t(i)]).dot(ts.axis);
      }
    }
    run.traces[t].push_back(value);
  }
}

// ------------------------------------------------------------------ runs

namespace {

bool finiteState(const OracleBodyState& s) {
  return s.position.allFinite() && s.orientation.coeffs().allFinite() && s.linear_velocity.allFinite() &&
         s.angular_velocity.allFinite();
}

// Bullet's states into the shadow World; false if any is not finite.
bool copyStates(const BulletOracle& oracle, World& shadow) {
  for (int i = 0; i < shadow.bodyCount(); ++i) {
    Body& b = cairn::detail::internals(shadow).body(BodyId{i});
    if (b.type == BodyType::Static) continue;
    const OracleBodyState s = oracle.state(i);
    if (!finiteState(s)) return false;
    b.position = s.position;
    b.orientation = s.orientation.normalized();
    b.linear_velocity = s.linear_velocity;
    b.angular_velocity = s.angular_velocity;
    b.updateDerived();
  }
  for (int j = 0; j < cairn::detail::internals(shadow).jointSlots(); ++j)
    if (!oracle.jointActive(j) && !cairn::detail::internals(shadow).joint(JointId{j}).broken) cairn::detail::internals(shadow).removeJoint(JointId{j});
  return true;
}

}  // namespace

CairnRunner::CairnRunner(const SceneDesc& scene, const ValidationSpec& spec, EngineRun& out, Replay* replay)
    : dt_(scene.dt), world_(buildWorld(scene)), recorder_(scene, spec), out_(out) {
  recorder_.record(world_, 0, 0, out_);
  if (replay) replay_ = std::make_unique<ReplayRecorder>(world_, dt_, *replay);
}

CairnRunner::~CairnRunner() = default;

bool CairnRunner::step(int s) {
  if (!running_) return false;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  world_.step(dt_);
  const double sec = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!world_.numericalEvents().empty()) {
    const auto& ev = world_.numericalEvents().front();
    out_.failure = "body '" + ev.body_name + "': non-finite state in " + ev.stage + " at step " + std::to_string(s);
    running_ = false;
    return false;
  }
  recorder_.record(world_, s * dt_, sec, out_);
  if (replay_) replay_->record(world_);
  return true;
}

BulletRunner::BulletRunner(const SceneDesc& scene, const ValidationSpec& spec, EngineRun& out,
                           const OracleOptions& options)
    : dt_(scene.dt), shadow_(buildWorld(scene)), oracle_(std::make_unique<BulletOracle>(scene, options)),
      recorder_(scene, spec), out_(out) {
  running_ = copyStates(*oracle_, shadow_);
  if (running_) recorder_.record(shadow_, 0, 0, out_);
  else out_.failure = "non-finite state at the start";
}

BulletRunner::~BulletRunner() = default;

bool BulletRunner::step(int s) {
  if (!running_) return false;
  oracle_->step();
  if (!copyStates(*oracle_, shadow_)) {
    out_.failure = "non-finite state at step " + std::to_string(s);
    running_ = false;
    return false;
  }
  recorder_.record(shadow_, s * dt_, oracle_->lastStepSeconds(), out_);
  return true;
}

const std::vector<std::string>& BulletRunner::skipped() const { return oracle_->skipped(); }

int BulletRunner::sleepingBodies() const { return oracle_->sleepingBodies(); }

void runDirectReference(const SceneDesc& scene, const ValidationSpec& spec, EngineRun& out) {
  SceneDesc exact = scene;
  exact.solver.method = SolverMethod::Direct;
  CairnRunner reference(exact, spec, out);
  for (int s = 1; s <= scene.steps; ++s)
    if (!reference.step(s)) break;
}

void runEngines(SceneResult& r, bool record_replay) {
  if (record_replay) r.replay = std::make_shared<Replay>();
  // One step each in turn, so both runs see the machine in the same state.
  CairnRunner cairn(r.scene, r.spec, r.cairn, r.replay.get());
  BulletRunner bullet(r.scene, r.spec, r.bullet);
  for (int s = 1; s <= r.scene.steps && (cairn.running() || bullet.running()); ++s) {
    cairn.step(s);
    bullet.step(s);
  }
  r.skipped = bullet.skipped();
  if (r.replay) {
    r.replay->title = r.name + ": cairn and Bullet";
    r.replay->source = r.source;
    addBulletRun(*r.replay, r.bullet, r.spec);
    fitContacts(*r.replay);
  }
  // The exact bilateral solve of the same scene, after the timed runs.
  if (r.spec.direct_reference) runDirectReference(r.scene, r.spec, r.reference);
}

SceneResult validateScene(const SceneDesc& scene, const std::string& name, const std::string& source,
                          const std::string& description, bool record_replay) {
  SceneResult r;
  r.name = name;
  r.source = source;
  r.description = description;
  r.scene = scene;
  r.spec = validationSpec(scene);
  runEngines(r, record_replay);
  r.figures = compareRuns(r.scene, r.spec, r.cairn, r.bullet, r.spec.direct_reference ? &r.reference : nullptr);
  return r;
}

}  // namespace cairn::validation
