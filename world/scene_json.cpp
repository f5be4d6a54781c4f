#include "world/scene_json.hpp"

#include "collision/hull.hpp"
#include "collision/obj_mesh.hpp"
#include "cairn/error.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace cairn {

using nlohmann::json;

namespace {

// Reads one JSON object, remembering which keys were used so that unknown
// keys (a typo such as "masss") are reported instead of silently ignored.
class Reader {
 public:
  Reader(const json& j, std::string object, std::string prefix = "")
      : j_(j), object_(std::move(object)), prefix_(std::move(prefix)) {
    if (!j_.is_object()) throw InputError(object_, prefix_.empty() ? "" : prefix_.substr(0, prefix_.size() - 1), "must be a JSON object");
  }

  bool has(const char* key) const {
    used_.insert(key);
    return j_.contains(key);
  }
  const json& raw(const char* key) const {
    used_.insert(key);
    return j_.at(key);
  }
  std::string field(const std::string& key) const { return prefix_ + key; }

  Real number(const char* key) const {
    const json& v = raw(key);
    if (!v.is_number()) fail(key, "must be a number");
    return v.get<Real>();
  }
  Real number(const char* key, Real def) const { return has(key) ? number(key) : def; }
  std::optional<Real> optNumber(const char* key) const {
    if (!has(key)) return std::nullopt;
    return number(key);
  }
  int integer(const char* key, int def) const {
    if (!has(key)) return def;
    const json& v = raw(key);
    if (!v.is_number_integer()) fail(key, "must be an integer");
    return v.get<int>();
  }
  bool boolean(const char* key, bool def) const {
    if (!has(key)) return def;
    const json& v = raw(key);
    if (!v.is_boolean()) fail(key, "must be true or false");
    return v.get<bool>();
  }
  std::string string(const char* key) const {
    const json& v = raw(key);
    if (!v.is_string()) fail(key, "must be a string");
    return v.get<std::string>();
  }
  std::string string(const char* key, const std::string& def) const { return has(key) ? string(key) : def; }
  Vec3 vec3(const char* key) const { return vec3Of(raw(key), key); }
  Vec3 vec3(const char* key, const Vec3& def) const { return has(key) ? vec3(key) : def; }
  Vec3 vec3Of(const json& v, const std::string& key) const {
    if (!v.is_array() || v.size() != 3) fail(key, "must be an array of 3 numbers");
    Vec3 r;
    for (int k = 0; k < 3; ++k) {
      if (!v[k].is_number()) fail(key, "must be an array of 3 numbers");
      r[k] = v[k].get<Real>();
    }
    return r;
  }
  Quat quat(const char* key) const {
    const json& v = raw(key);
    if (!v.is_array() || v.size() != 4) fail(key, "must be an array [w, x, y, z]");
    Real c[4];
    for (int k = 0; k < 4; ++k) {
      if (!v[k].is_number()) fail(key, "must be an array [w, x, y, z]");
      c[k] = v[k].get<Real>();
    }
    Quat q(c[0], c[1], c[2], c[3]);
    if (!q.coeffs().allFinite()) fail(key, "must be finite");
    if (q.norm() < Real(1e-9)) fail(key, "zero-length quaternion");
    return q.normalized();
  }
  Quat quat(const char* key, const Quat& def) const { return has(key) ? quat(key) : def; }
  Mat3 mat3(const char* key) const {
    const json& v = raw(key);
    Mat3 m;
    if (!v.is_array() || v.size() != 3) fail(key, "must be a 3x3 array of numbers");
    for (int r = 0; r < 3; ++r) {
      if (!v[r].is_array() || v[r].size() != 3) fail(key, "must be a 3x3 array of numbers");
      for (int c = 0; c < 3; ++c) {
        if (!v[r][c].is_number()) fail(key, "must be a 3x3 array of numbers");
        m(r, c) = v[r][c].get<Real>();
      }
    }
    return m;
  }

  [[noreturn]] void fail(const std::string& key, const std::string& msg) const {
    throw InputError(object_, prefix_ + key, msg);
  }

  // Every key must have been read by now.
  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it)
      if (!used_.count(it.key())) throw InputError(object_, prefix_ + it.key(), "unknown key");
  }

  const std::string& object() const { return object_; }

 private:
  const json& j_;
  std::string object_, prefix_;
  mutable std::set<std::string> used_;
};

ShapeDesc parseShape(const json& j, const std::string& object, const std::string& prefix,
                     const std::filesystem::path& base_dir) {
  Reader r(j, object, prefix);
  if (!r.has("type")) r.fail("type", "missing shape type");
  const std::string type = r.string("type");
  ShapeDesc s;
  if (type == "sphere") {
    s.type = ShapeType::Sphere;
    s.radius = r.number("radius");
  } else if (type == "box") {
    s.type = ShapeType::Box;
    s.half_extents = r.vec3("half_extents");
  } else if (type == "capsule" || type == "cylinder") {
    s.type = type == "capsule" ? ShapeType::Capsule : ShapeType::Cylinder;
    s.radius = r.number("radius");
    s.half_height = r.number("half_height");
  } else if (type == "plane") {
    s.type = ShapeType::Plane;
    s.normal = r.vec3("normal");
    if (s.normal.allFinite() && s.normal.norm() > 0) s.normal.normalize();
    s.offset = r.number("offset", 0);
  } else if (type == "convex_hull") {
    s.type = ShapeType::ConvexHull;
    const json& pts = r.raw("points");
    if (!pts.is_array()) r.fail("points", "must be an array of [x, y, z] points");
    std::vector<Vec3> points;
    for (size_t i = 0; i < pts.size(); ++i) points.push_back(r.vec3Of(pts[i], "points[" + std::to_string(i) + "]"));
    s.hull = buildConvexHull(points, object, r.field("points"));
  } else if (type == "mesh") {
    s.type = ShapeType::Mesh;
    const std::string rel = r.string("obj");
    const std::filesystem::path p = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : base_dir / rel;
    s.source = p.string();
    s.mesh = loadObjMesh(p.string(), object, r.field("obj"));
  } else {
    r.fail("type", "unknown shape type '" + type + "' (sphere, box, capsule, cylinder, plane, convex_hull, mesh)");
  }
  if (r.has("position")) s.local.p = r.vec3("position");
  if (r.has("orientation")) s.local.q = r.quat("orientation");
  r.finish();
  return s;
}

// An array of [x, y, z] vectors (DOF lock axes); absent: none.
std::vector<Vec3> vec3List(const Reader& r, const char* key) {
  std::vector<Vec3> out;
  if (!r.has(key)) return out;
  const json& v = r.raw(key);
  if (!v.is_array()) r.fail(key, "must be an array of [x, y, z] axes");
  for (size_t i = 0; i < v.size(); ++i) out.push_back(r.vec3Of(v[i], std::string(key) + "[" + std::to_string(i) + "]"));
  return out;
}

BodyDef parseBody(const json& j, size_t index, const std::filesystem::path& base_dir) {
  std::string object = "body #" + std::to_string(index);
  if (j.is_object() && j.contains("name") && j["name"].is_string()) object = "body '" + j["name"].get<std::string>() + "'";
  Reader r(j, object);
  BodyDef b;
  if (!r.has("name")) r.fail("name", "missing body name");
  b.name = r.string("name");
  if (b.name.empty() || b.name == "world") r.fail("name", "must be a non-empty name other than 'world'");
  const std::string type = r.string("type", "dynamic");
  if (type == "dynamic") b.type = BodyType::Dynamic;
  else if (type == "static") b.type = BodyType::Static;
  else if (type == "kinematic") b.type = BodyType::Kinematic;
  else r.fail("type", "must be dynamic, static or kinematic (got '" + type + "')");
  b.mass = r.optNumber("mass");
  b.density = r.optNumber("density");
  if (r.has("inertia")) b.inertia = r.mat3("inertia");
  b.position = r.vec3("position", Vec3::Zero());
  b.orientation = r.quat("orientation", Quat::Identity());
  b.linear_velocity = r.vec3("linear_velocity", Vec3::Zero());
  b.angular_velocity = r.vec3("angular_velocity", Vec3::Zero());
  b.friction = r.number("friction", b.friction);
  b.restitution = r.number("restitution", b.restitution);
  b.rolling_friction = r.number("rolling_friction", 0);
  b.torsional_friction = r.number("torsional_friction", 0);
  b.linear_damping = r.number("linear_damping", 0);
  b.angular_damping = r.number("angular_damping", 0);
  b.ccd = r.boolean("ccd", false);
  if (r.has("collision_group")) b.collision_group = static_cast<std::uint32_t>(r.integer("collision_group", 1));
  if (r.has("collision_mask")) b.collision_mask = static_cast<std::uint32_t>(r.raw("collision_mask").get<std::int64_t>());
  if (r.has("shapes")) {
    const json& shapes = r.raw("shapes");
    if (!shapes.is_array()) r.fail("shapes", "must be an array");
    for (size_t i = 0; i < shapes.size(); ++i)
      b.shapes.push_back(parseShape(shapes[i], object, "shapes[" + std::to_string(i) + "].", base_dir));
  }
  b.force = r.vec3("force", Vec3::Zero());
  b.torque = r.vec3("torque", Vec3::Zero());
  if (r.has("impulses")) {
    const json& imps = r.raw("impulses");
    if (!imps.is_array()) r.fail("impulses", "must be an array of {time, impulse, point}");
    for (size_t i = 0; i < imps.size(); ++i) {
      Reader ir(imps[i], object, "impulses[" + std::to_string(i) + "].");
      BodyDef::TimedImpulse imp;
      if (!ir.has("time")) ir.fail("time", "missing: the time (s) the impulse is applied at");
      if (!ir.has("impulse")) ir.fail("impulse", "missing: the impulse [x, y, z] (N s)");
      imp.time = ir.number("time");
      imp.impulse = ir.vec3("impulse");
      if (ir.has("point")) imp.point = ir.vec3("point");
      ir.finish();
      b.impulses.push_back(imp);
    }
  }
  b.lock_translation = vec3List(r, "lock_translation");
  b.lock_rotation = vec3List(r, "lock_rotation");
  r.finish();
  return b;
}

BodyId bodyRef(const Reader& r, const SceneDesc& scene, const json& v, const std::string& field) {
  if (!v.is_string()) r.fail(field, "must be a body name or \"world\"");
  const std::string name = v.get<std::string>();
  if (name == "world") return kWorldBody;
  const int idx = scene.bodyIndex(name);
  if (idx < 0) r.fail(field, "no body named '" + name + "'");
  return BodyId{idx};
}

std::pair<BodyId, BodyId> bodyPair(const Reader& r, const SceneDesc& scene) {
  if (!r.has("bodies")) r.fail("bodies", "missing: give [a, b] with body names or \"world\"");
  const json& v = r.raw("bodies");
  if (!v.is_array() || v.size() != 2) r.fail("bodies", "must be [a, b] with body names or \"world\"");
  return {bodyRef(r, scene, v[0], "bodies[0]"), bodyRef(r, scene, v[1], "bodies[1]")};
}

Softness parseSoftness(const Reader& r) {
  Softness s;
  s.erp = r.optNumber("erp");
  s.cfm = r.optNumber("cfm");
  s.stiffness = r.optNumber("stiffness");
  s.damping = r.optNumber("damping");
  s.frequency = r.optNumber("frequency");
  s.damping_ratio = r.optNumber("damping_ratio");
  return s;
}

LimitDef parseLimit(const json& j, const std::string& object, const std::string& prefix) {
  Reader r(j, object, prefix);
  LimitDef l;
  l.enabled = true;
  l.lower = r.number("lower");
  l.upper = r.number("upper");
  l.restitution = r.number("restitution", 0);
  l.softness = parseSoftness(r);
  r.finish();
  return l;
}

MotorDef parseMotor(const json& j, const std::string& object, const std::string& prefix) {
  Reader m(j, object, prefix);
  MotorDef d;
  d.enabled = m.boolean("enabled", true);
  d.target_position = m.optNumber("target_position");
  if (!d.target_position && !m.has("target_velocity"))
    m.fail("target_velocity", "missing: a motor needs target_velocity (a velocity motor) or target_position (a servo)");
  d.target_velocity = m.number("target_velocity", 0);
  d.max_force = m.optNumber("max_force");
  d.softness = parseSoftness(m);
  m.finish();
  return d;
}

DofDef parseDof(const json& j, const std::string& object, const std::string& prefix) {
  Reader r(j, object, prefix);
  DofDef d;
  const std::string mode = r.string("mode", "free");
  if (mode == "free") d.mode = DofMode::Free;
  else if (mode == "limited") d.mode = DofMode::Limited;
  else if (mode == "locked") d.mode = DofMode::Locked;
  else r.fail("mode", "must be free, limited or locked (got '" + mode + "')");
  if (d.mode == DofMode::Limited && !r.has("limits")) r.fail("limits", "a limited axis needs limits {lower, upper}");
  if (r.has("limits")) d.limit = parseLimit(r.raw("limits"), object, prefix + "limits.");
  if (r.has("spring")) {
    Reader sp(r.raw("spring"), object, prefix + "spring.");
    d.spring.enabled = true;
    d.spring.rest = sp.number("rest", 0);
    d.spring.softness = parseSoftness(sp);
    sp.finish();
  }
  if (r.has("motor")) d.motor = parseMotor(r.raw("motor"), object, prefix + "motor.");
  r.finish();
  return d;
}

JointType jointType(const Reader& r, const std::string& t) {
  if (t == "ball") return JointType::Ball;
  if (t == "hinge") return JointType::Hinge;
  if (t == "slider") return JointType::Slider;
  if (t == "fixed") return JointType::Fixed;
  if (t == "universal") return JointType::Universal;
  if (t == "cone_twist") return JointType::ConeTwist;
  if (t == "distance") return JointType::Distance;
  if (t == "angular_motor") return JointType::AngularMotor;
  if (t == "six_dof") return JointType::SixDof;
  r.fail("type", "unknown joint type '" + t +
                     "' (ball, hinge, slider, fixed, universal, cone_twist, distance, angular_motor, six_dof)");
}

JointDef parseJoint(const json& j, size_t index, const SceneDesc& scene) {
  std::string object = "joint #" + std::to_string(index);
  if (j.is_object() && j.contains("name") && j["name"].is_string()) object = "joint '" + j["name"].get<std::string>() + "'";
  Reader r(j, object);
  JointDef d;
  d.name = r.string("name", "joint" + std::to_string(index));
  if (!r.has("type")) r.fail("type", "missing joint type");
  d.type = jointType(r, r.string("type"));
  std::tie(d.body_a, d.body_b) = bodyPair(r, scene);
  if (d.type == JointType::Distance) {
    if (!r.has("anchors")) r.fail("anchors", "a distance joint needs two world points");
    const json& a = r.raw("anchors");
    if (!a.is_array() || a.size() != 2) r.fail("anchors", "must be two world points [[x,y,z],[x,y,z]]");
    d.anchor_a = r.vec3Of(a[0], "anchors[0]");
    d.anchor_b = r.vec3Of(a[1], "anchors[1]");
    d.length = r.optNumber("length");
  } else {
    d.anchor = r.vec3("anchor", Vec3::Zero());
  }
  d.axis = r.vec3("axis", d.axis);
  d.axis2 = r.vec3("axis2", d.axis2);
  if (r.has("limits")) d.limit = parseLimit(r.raw("limits"), object, "limits.");
  if (r.has("swing_span1")) d.swing_span1 = r.number("swing_span1");
  if (r.has("swing_span2")) d.swing_span2 = r.number("swing_span2");
  if (r.has("motor")) {
    const json& mj = r.raw("motor");
    if (d.type == JointType::AngularMotor) {
      if (!mj.is_array()) r.fail("motor", "an angular motor takes an array of {axis, target_velocity, max_force}");
      for (size_t i = 0; i < mj.size(); ++i) {
        Reader m(mj[i], object, "motor[" + std::to_string(i) + "].");
        d.motor_axes.push_back(m.vec3("axis"));
        d.motor_targets.push_back(m.number("target_velocity"));
        d.motor_max_torques.push_back(m.number("max_force"));
        m.finish();
      }
    } else {
      d.motor = parseMotor(mj, object, "motor.");
    }
  }
  if (r.has("dofs")) {
    if (d.type != JointType::SixDof) r.fail("dofs", "only a six_dof joint has dofs");
    Reader dofs(r.raw("dofs"), object, "dofs.");
    for (int i = 0; i < kDofCount; ++i)
      if (dofs.has(dofName(i)))
        d.dofs[static_cast<size_t>(i)] = parseDof(dofs.raw(dofName(i)), object, std::string("dofs.") + dofName(i) + ".");
    dofs.finish();
  }
  d.softness = parseSoftness(r);
  d.break_force = r.number("break_force", kInf);
  d.break_torque = r.number("break_torque", kInf);
  d.collide_connected = r.boolean("collide_connected", false);
  r.finish();
  return d;
}

Gyroscopic parseGyro(const Reader& r, const std::string& s) {
  if (s == "off") return Gyroscopic::Off;
  if (s == "explicit") return Gyroscopic::Explicit;
  if (s == "implicit_euler") return Gyroscopic::ImplicitEuler;
  if (s == "implicit_midpoint") return Gyroscopic::ImplicitMidpoint;
  r.fail("gyroscopic", "must be off, explicit, implicit_euler or implicit_midpoint (got '" + s + "')");
}

SolverMethod parseMethod(const Reader& r, const std::string& s) {
  if (s == "pgs") return SolverMethod::PGS;
  if (s == "direct") return SolverMethod::Direct;
  if (s == "lcp") return SolverMethod::LCP;
  r.fail("method", "must be pgs, direct or lcp (got '" + s + "')");
}

SolverSettings parseSolver(const json& j) {
  Reader r(j, "solver");
  SolverSettings s;
  if (r.has("method")) s.method = parseMethod(r, r.string("method"));
  s.iterations = r.integer("iterations", s.iterations);
  s.tolerance = r.number("tolerance", s.tolerance);
  s.sor = r.number("sor", s.sor);
  s.warm_start = r.boolean("warm_start", s.warm_start);
  s.warm_start_factor = r.number("warm_start_factor", s.warm_start_factor);
  s.randomize_order = r.boolean("randomize_order", s.randomize_order);
  s.nncg = r.boolean("nncg", s.nncg);
  if (r.has("seed")) s.seed = r.raw("seed").get<std::uint64_t>();
  s.substeps = r.integer("substeps", s.substeps);
  s.erp = r.number("erp", s.erp);
  s.cfm = r.number("cfm", s.cfm);
  s.contact_erp = r.number("contact_erp", s.contact_erp);
  s.slop = r.number("slop", s.slop);
  s.restitution_threshold = r.number("restitution_threshold", s.restitution_threshold);
  s.split_impulse = r.boolean("split_impulse", s.split_impulse);
  if (r.has("position_correction")) {
    const std::string pc = r.string("position_correction");
    if (pc == "baumgarte") s.position_correction = Correction::VelocityBias;
    else if (pc == "split") s.position_correction = Correction::PseudoVelocity;
    else if (pc == "single_pass") s.position_correction = Correction::InRhs;
    else r.fail("position_correction", "must be baumgarte, split or single_pass (got '" + pc + "')");
  }
  s.max_correction_velocity = r.number("max_correction_velocity", s.max_correction_velocity);
  s.contact_margin = r.number("contact_margin", s.contact_margin);
  s.sleeping = r.boolean("sleeping", s.sleeping);
  s.sleep_linear_velocity = r.number("sleep_linear_velocity", s.sleep_linear_velocity);
  s.sleep_angular_velocity = r.number("sleep_angular_velocity", s.sleep_angular_velocity);
  s.sleep_time = r.number("sleep_time", s.sleep_time);
  s.max_angular_velocity = r.number("max_angular_velocity", s.max_angular_velocity);
  if (r.has("gyroscopic")) s.gyroscopic = parseGyro(r, r.string("gyroscopic"));
  if (r.has("orientation")) {
    const std::string o = r.string("orientation");
    if (o == "exponential_map") s.orientation = OrientationIntegrator::ExponentialMap;
    else if (o == "derivative") s.orientation = OrientationIntegrator::Derivative;
    else r.fail("orientation", "must be exponential_map or derivative (got '" + o + "')");
  }
  r.finish();
  return s;
}

std::string lineOf(const std::string& text, size_t byte) {
  size_t line = 1, col = 1;
  for (size_t i = 0; i < std::min(byte, text.size()); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

}  // namespace

SceneDesc parseScene(const std::string& text, const std::string& path) {
  try {
    json j;
    try {
      j = json::parse(text);
    } catch (const json::parse_error& e) {
      throw InputError("", "", "malformed JSON at " + lineOf(text, e.byte == 0 ? 0 : e.byte - 1) + ": " + e.what());
    } catch (const json::exception& e) {
      // Number overflow (e.g. 1e999, JSON's only way to spell a non-finite
      // value): locate the quoted token for the line number.
      const std::string what = e.what();
      const auto q1 = what.find('\''), q2 = what.rfind('\'');
      const auto at = q1 != std::string::npos && q2 > q1 ? text.find(what.substr(q1 + 1, q2 - q1 - 1)) : std::string::npos;
      throw InputError("", "", "malformed JSON" + (at == std::string::npos ? std::string() : " at " + lineOf(text, at)) +
                                   ": " + what + " (numbers must be finite)");
    }
    const std::filesystem::path base_dir = std::filesystem::path(path).parent_path();
    Reader r(j, "scene");
    SceneDesc scene;
    scene.path = path;
    scene.gravity = r.vec3("gravity", scene.gravity);
    scene.dt = r.number("dt", scene.dt);
    scene.steps = r.integer("steps", scene.steps);
    if (r.has("solver")) scene.solver = parseSolver(r.raw("solver"));
    if (r.has("bodies")) {
      const json& bodies = r.raw("bodies");
      if (!bodies.is_array()) r.fail("bodies", "must be an array");
      for (size_t i = 0; i < bodies.size(); ++i) scene.bodies.push_back(parseBody(bodies[i], i, base_dir));
    }
    if (r.has("springs")) {
      const json& springs = r.raw("springs");
      if (!springs.is_array()) r.fail("springs", "must be an array");
      for (size_t i = 0; i < springs.size(); ++i) {
        Reader s(springs[i], "spring #" + std::to_string(i));
        SpringDef d;
        d.name = s.string("name", "spring" + std::to_string(i));
        std::tie(d.body_a, d.body_b) = bodyPair(s, scene);
        if (!s.has("anchors")) s.fail("anchors", "missing: two world points");
        const json& a = s.raw("anchors");
        if (!a.is_array() || a.size() != 2) s.fail("anchors", "must be two world points [[x,y,z],[x,y,z]]");
        d.anchor_a = s.vec3Of(a[0], "anchors[0]");
        d.anchor_b = s.vec3Of(a[1], "anchors[1]");
        d.rest_length = s.optNumber("rest_length");
        d.stiffness = s.number("stiffness");
        d.damping = s.number("damping", 0);
        s.finish();
        scene.springs.push_back(d);
      }
    }
    if (r.has("joints")) {
      const json& joints = r.raw("joints");
      if (!joints.is_array()) r.fail("joints", "must be an array");
      for (size_t i = 0; i < joints.size(); ++i) scene.joints.push_back(parseJoint(joints[i], i, scene));
    }
    if (r.has("validation")) scene.validation_json = r.raw("validation").dump();
    if (r.has("description")) (void)r.raw("description");
    r.finish();
    validateScene(scene);
    return scene;
  } catch (const InputError& e) {
    const std::string obj = e.object().empty() ? path : path + ": " + e.object();
    throw InputError(obj, e.field(), e.message());
  }
}

SceneDesc loadScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot open scene file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseScene(ss.str(), path);
}

}  // namespace cairn
