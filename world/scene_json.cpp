#include "world/scene_json.hpp"

#include "world/def_checks.hpp"

#include "collision/hull.hpp"
#include "collision/obj_mesh.hpp"
#include "cairn/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <unordered_map>
#include <sstream>

namespace cairn {

using nlohmann::json;

namespace {

bool isPrintableName(const std::string& s) {
  return std::none_of(s.begin(), s.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; });
}

// Reads one JSON object, remembering which keys were used so that unknown
// keys (a typo such as "masss") are reported instead of silently ignored.
// Every read checks the key's presence and JSON type and, for integers,
// that the value fits the field (never wrapped): a bad file ends in an
// InputError naming the object, the field and what is allowed, never in a
// nlohmann exception.
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
  // The value of a required key; `expected` says what it must be.
  const json& required(const char* key, const std::string& expected) const {
    if (!has(key)) fail(key, "missing: " + expected);
    return j_.find(key).value();
  }
  std::string field(const std::string& key) const { return prefix_ + key; }
  // A nested value its own Reader or parser checks (an object's type is
  // checked by the Reader made from it).
  const json& raw(const char* key) const { return required(key, "a value"); }

  Real number(const char* key) const { return numberOf(required(key, "a number"), key); }
  Real number(const char* key, Real def) const { return has(key) ? number(key) : def; }
  std::optional<Real> optNumber(const char* key) const {
    if (!has(key)) return std::nullopt;
    return number(key);
  }
  Real numberOf(const json& v, const std::string& key) const {
    if (!v.is_number()) fail(key, "must be a number" + got(v));
    return v.get<Real>();
  }
  // A non-negative integer in [lo, hi]: larger values are refused, never
  // wrapped into the field's type.
  std::uint64_t integer(const char* key, std::uint64_t lo, std::uint64_t hi) const {
    const json& v = required(key, "an integer");
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() < lo || v.get<std::uint64_t>() > hi)
      fail(key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]" + got(v));
    return v.get<std::uint64_t>();
  }
  int intIn(const char* key, int def, int lo) const {
    return has(key) ? static_cast<int>(integer(key, static_cast<std::uint64_t>(lo), std::numeric_limits<int>::max())) : def;
  }
  std::uint32_t u32(const char* key, std::uint32_t def) const {
    return has(key) ? static_cast<std::uint32_t>(integer(key, 0, std::numeric_limits<std::uint32_t>::max())) : def;
  }
  std::uint64_t u64(const char* key, std::uint64_t def) const {
    return has(key) ? integer(key, 0, std::numeric_limits<std::uint64_t>::max()) : def;
  }
  bool boolean(const char* key, bool def) const {
    if (!has(key)) return def;
    const json& v = required(key, "true or false");
    if (!v.is_boolean()) fail(key, "must be true or false" + got(v));
    return v.get<bool>();
  }
  std::string string(const char* key) const {
    const json& v = required(key, "a string");
    if (!v.is_string()) fail(key, "must be a string" + got(v));
    return v.get<std::string>();
  }
  std::string string(const char* key, const std::string& def) const { return has(key) ? string(key) : def; }
  // A name: a string without control characters (it appears in messages,
  // CSV rows and metrics as it is).
  std::string name(const char* key) const {
    std::string s = string(key);
    if (!isPrintableName(s)) fail(key, "must be a name without control characters (U+0000 to U+001F, U+007F)");
    return s;
  }
  std::string name(const char* key, const std::string& def) const { return has(key) ? name(key) : def; }
  const json& array(const char* key, const std::string& expected) const {
    const json& v = required(key, expected);
    if (!v.is_array()) fail(key, "must be " + expected + got(v));
    return v;
  }
  Vec3 vec3(const char* key) const { return vec3Of(required(key, "an array of 3 numbers"), key); }
  Vec3 vec3(const char* key, const Vec3& def) const { return has(key) ? vec3(key) : def; }
  Vec3 vec3Of(const json& v, const std::string& key) const {
    if (!v.is_array() || v.size() != 3) fail(key, "must be an array of 3 numbers" + got(v));
    Vec3 r;
    for (int k = 0; k < 3; ++k) {
      if (!v[k].is_number()) fail(key, "must be an array of 3 numbers" + got(v));
      r[k] = v[k].get<Real>();
    }
    return r;
  }
  Quat quat(const char* key) const {
    const json& v = required(key, "an array [w, x, y, z]");
    if (!v.is_array() || v.size() != 4) fail(key, "must be an array [w, x, y, z]" + got(v));
    Real c[4];
    for (int k = 0; k < 4; ++k) {
      if (!v[k].is_number()) fail(key, "must be an array [w, x, y, z]" + got(v));
      c[k] = v[k].get<Real>();
    }
    // A quaternion whose squared norm would overflow or underflow is scaled
    // first (Eigen's norm() squares); one of ordinary size is normalized as
    // written, so a unit quaternion reads back to the same bits.
    const Real big = std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2]), std::abs(c[3])});
    if (!(big > 0)) fail(key, "zero-length quaternion");
    const Real scale = big > Real(1e-150) && big < Real(1e150) ? Real(1) : big;
    Quat q(c[0] / scale, c[1] / scale, c[2] / scale, c[3] / scale);
    if (!q.coeffs().allFinite()) fail(key, "must be finite");
    return q.normalized();
  }
  Quat quat(const char* key, const Quat& def) const { return has(key) ? quat(key) : def; }
  Mat3 mat3(const char* key) const {
    const json& v = required(key, "a 3x3 array of numbers");
    Mat3 m;
    if (!v.is_array() || v.size() != 3) fail(key, "must be a 3x3 array of numbers" + got(v));
    for (int r = 0; r < 3; ++r) {
      if (!v[r].is_array() || v[r].size() != 3) fail(key, "must be a 3x3 array of numbers" + got(v));
      for (int c = 0; c < 3; ++c) {
        if (!v[r][c].is_number()) fail(key, "must be a 3x3 array of numbers" + got(v));
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
  // " (got VALUE)": what was found, shortened (it may be anything).
  static std::string got(const json& v) {
    if (v.is_array()) return " (got an array of " + std::to_string(v.size()) + ")";
    if (v.is_object()) return " (got an object)";
    std::string t = v.dump(-1, ' ', false, json::error_handler_t::replace);
    if (t.size() > 40) t = t.substr(0, 37) + "...";
    return " (got " + t + ")";
  }

  const json& j_;
  std::string object_, prefix_;
  mutable std::set<std::string> used_;
};

// "body 'crate'" when the entry has a usable name, else "body #3".
std::string objectLabel(const char* kind, const json& j, size_t index) {
  if (j.is_object()) {
    const auto it = j.find("name");
    if (it != j.end() && it->is_string() && isPrintableName(it->get<std::string>()))
      return std::string(kind) + " '" + it->get<std::string>() + "'";
  }
  return std::string(kind) + " #" + std::to_string(index);
}

// What every part of a scene is read with: where relative mesh paths start
// and the input limits.
struct Context {
  std::filesystem::path base_dir;
  const InputLimits& limits;
};

// Refuses an array longer than `limit` before anything is built from it.
void checkCount(const Reader& r, const char* key, const json& array, std::uint64_t limit, const char* name) {
  if (array.size() > limit) r.fail(key, std::to_string(array.size()) + " entries exceed the limit " + limitHint(name, limit));
}

// The direction of v, normalized without squaring huge or tiny components
// into infinity or zero (Eigen's normalized() squares first); v unchanged
// when it has no direction.
Vec3 direction(const Vec3& v) {
  if (!v.allFinite()) return v;
  const Real big = v.cwiseAbs().maxCoeff();
  return big > 0 ? Vec3(v / big).normalized() : v;
}

ShapeDesc parseShape(const json& j, const std::string& object, const std::string& prefix, const Context& ctx) {
  Reader r(j, object, prefix);
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
    s.normal = direction(r.vec3("normal"));
    s.offset = r.number("offset", 0);
  } else if (type == "convex_hull") {
    s.type = ShapeType::ConvexHull;
    const json& pts = r.array("points", "an array of [x, y, z] points");
    checkCount(r, "points", pts, ctx.limits.hull_points, "hull_points");
    std::vector<Vec3> points;
    points.reserve(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) points.push_back(r.vec3Of(pts[i], "points[" + std::to_string(i) + "]"));
    s.hull = buildConvexHull(points, object, r.field("points"), ctx.limits);
  } else if (type == "mesh") {
    s.type = ShapeType::Mesh;
    const std::string rel = r.string("obj");
    const std::filesystem::path p = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : ctx.base_dir / rel;
    s.source = p.string();
    s.mesh = loadObjMesh(p.string(), object, r.field("obj"), ctx.limits);
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
  const json& v = r.array(key, "an array of [x, y, z] axes");
  for (size_t i = 0; i < v.size(); ++i) out.push_back(r.vec3Of(v[i], std::string(key) + "[" + std::to_string(i) + "]"));
  return out;
}

BodyDef parseBody(const json& j, size_t index, const Context& ctx) {
  Reader r(j, objectLabel("body", j, index));
  const std::string& object = r.object();
  BodyDef b;
  b.name = r.name("name");
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
  b.collision_group = r.u32("collision_group", b.collision_group);
  b.collision_mask = r.u32("collision_mask", b.collision_mask);
  if (r.has("shapes")) {
    const json& shapes = r.array("shapes", "an array of shapes");
    checkCount(r, "shapes", shapes, ctx.limits.shapes_per_body, "shapes_per_body");
    b.shapes.reserve(shapes.size());
    for (size_t i = 0; i < shapes.size(); ++i)
      b.shapes.push_back(parseShape(shapes[i], object, "shapes[" + std::to_string(i) + "].", ctx));
  }
  b.force = r.vec3("force", Vec3::Zero());
  b.torque = r.vec3("torque", Vec3::Zero());
  if (r.has("impulses")) {
    const json& imps = r.array("impulses", "an array of {time, impulse, point}");
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

// Body names to indices, so that each reference of a joint or spring is
// found in constant time (a linear search per reference is quadratic in a
// large scene). The first of two bodies with the same name wins here; the
// World refuses the second.
using BodyNames = std::unordered_map<std::string, int>;

BodyNames bodyNames(const SceneDesc& scene) {
  BodyNames names;
  names.reserve(scene.bodies.size());
  for (size_t i = 0; i < scene.bodies.size(); ++i) names.emplace(scene.bodies[i].name, static_cast<int>(i));
  return names;
}

BodyId bodyRef(const Reader& r, const BodyNames& names, const json& v, const std::string& field) {
  if (!v.is_string()) r.fail(field, "must be a body name or \"world\"");
  const std::string name = v.get<std::string>();
  if (name == "world") return kWorldBody;
  const auto it = names.find(name);
  if (it == names.end()) r.fail(field, "no body named '" + name + "'");
  return BodyId{it->second};
}

std::pair<BodyId, BodyId> bodyPair(const Reader& r, const BodyNames& names) {
  const json& v = r.required("bodies", "[a, b] with body names or \"world\"");
  if (!v.is_array() || v.size() != 2) r.fail("bodies", "must be [a, b] with body names or \"world\"");
  return {bodyRef(r, names, v[0], "bodies[0]"), bodyRef(r, names, v[1], "bodies[1]")};
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

JointDef parseJoint(const json& j, size_t index, const BodyNames& names) {
  Reader r(j, objectLabel("joint", j, index));
  const std::string& object = r.object();
  JointDef d;
  d.name = r.name("name", "joint" + std::to_string(index));
  d.type = jointType(r, r.string("type"));
  std::tie(d.body_a, d.body_b) = bodyPair(r, names);
  if (d.type == JointType::Distance) {
    const json& a = r.required("anchors", "a distance joint needs two world points [[x,y,z],[x,y,z]]");
    if (!a.is_array() || a.size() != 2) r.fail("anchors", "must be two world points [[x,y,z],[x,y,z]]");
    d.anchor_a = r.vec3Of(a[0], "anchors[0]");
    d.anchor_b = r.vec3Of(a[1], "anchors[1]");
    d.length = r.optNumber("length");
  } else {
    d.anchor = r.vec3("anchor", Vec3::Zero());
  }
  d.axis = r.vec3("axis", d.axis);
  d.axis2 = r.vec3("axis2", d.axis2);
  if (r.has("limits")) d.limit = parseLimit(r.required("limits", "an object"), object, "limits.");
  if (r.has("swing_span1")) d.swing_span1 = r.number("swing_span1");
  if (r.has("swing_span2")) d.swing_span2 = r.number("swing_span2");
  if (r.has("motor")) {
    const json& mj = r.required("motor", "an object");
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
  if (s == "auto") return SolverMethod::Auto;
  r.fail("method", "must be auto, pgs, direct or lcp (got '" + s + "')");
}

SolverSettings parseSolver(const json& j) {
  Reader r(j, "solver");
  SolverSettings s;
  if (r.has("method")) s.method = parseMethod(r, r.string("method"));
  s.iterations = r.intIn("iterations", s.iterations, 1);
  s.position_iterations = r.intIn("position_iterations", s.position_iterations, 0);
  s.geometric_stiffness = r.boolean("geometric_stiffness", s.geometric_stiffness);
  s.tolerance = r.number("tolerance", s.tolerance);
  s.sor = r.number("sor", s.sor);
  s.warm_start = r.boolean("warm_start", s.warm_start);
  s.warm_start_factor = r.number("warm_start_factor", s.warm_start_factor);
  s.randomize_order = r.boolean("randomize_order", s.randomize_order);
  s.nncg = r.boolean("nncg", s.nncg);
  s.seed = r.u64("seed", s.seed);
  s.substeps = r.intIn("substeps", s.substeps, 1);
  s.prepare_contacts_each_substep = r.boolean("prepare_contacts_each_substep", s.prepare_contacts_each_substep);
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
  s.friction_directions = r.intIn("friction_directions", s.friction_directions, 1);
  s.patch_friction = r.boolean("patch_friction", s.patch_friction);
  s.contact_margin = r.number("contact_margin", s.contact_margin);
  s.recycle_distance = r.number("recycle_distance", s.recycle_distance);
  s.recycle_angle = r.number("recycle_angle", s.recycle_angle);
  s.sleeping = r.boolean("sleeping", s.sleeping);
  s.sleep_linear_velocity = r.number("sleep_linear_velocity", s.sleep_linear_velocity);
  s.sleep_angular_velocity = r.number("sleep_angular_velocity", s.sleep_angular_velocity);
  s.sleep_time = r.number("sleep_time", s.sleep_time);
  s.max_angular_velocity = r.number("max_angular_velocity", s.max_angular_velocity);
  s.max_pairs_per_shape = r.intIn("max_pairs_per_shape", s.max_pairs_per_shape, 1);
  s.max_exact_rows = r.intIn("max_exact_rows", s.max_exact_rows, 1);
  s.energy_rise = r.number("energy_rise", s.energy_rise);
  s.joint_drift = r.number("joint_drift", s.joint_drift);
  s.joint_drift_angle = r.number("joint_drift_angle", s.joint_drift_angle);
  s.penetration_drift = r.number("penetration_drift", s.penetration_drift);
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

// Parses JSON text with its nesting depth limited while parsing, so that
// nothing after (copying, dumping, destroying the value, all recursive in
// nlohmann::json) can exhaust the stack, and a number too large for a
// double (1e999, JSON's only spelling of infinity) refused with its line.
json parseJson(const std::string& text, const InputLimits& limits) {
  if (text.size() > limits.file_bytes)
    throw InputError("", "", std::to_string(text.size()) + " bytes exceed the limit " + limitHint("file_bytes", limits.file_bytes));
  struct TooDeep {};
  const json::parser_callback_t depth_check = [&](int depth, json::parse_event_t event, json&) {
    // `depth` counts the containers already open around this one.
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        static_cast<std::uint64_t>(depth) >= limits.json_depth)
      throw TooDeep{};
    return true;
  };
  try {
    return json::parse(text, depth_check);
  } catch (const TooDeep&) {
    throw InputError("", "", "arrays and objects nested more than " + std::to_string(limits.json_depth) + " deep " +
                                 limitHint("json_depth", limits.json_depth));
  } catch (const json::parse_error& e) {
    throw InputError("", "", "malformed JSON at " + lineOf(text, e.byte == 0 ? 0 : e.byte - 1) + ": " + e.what());
  } catch (const json::exception& e) {
    // Number overflow (e.g. 1e999): locate the quoted token for the line.
    const std::string what = e.what();
    const auto q1 = what.find('\''), q2 = what.rfind('\'');
    const auto at = q1 != std::string::npos && q2 > q1 ? text.find(what.substr(q1 + 1, q2 - q1 - 1)) : std::string::npos;
    throw InputError("", "", "malformed JSON" + (at == std::string::npos ? std::string() : " at " + lineOf(text, at)) +
                                 ": " + what + " (numbers must be finite)");
  }
}

}  // namespace

SceneDesc parseScene(const std::string& text, const std::string& path, const InputLimits& limits) {
  try {
    const json j = parseJson(text, limits);
    const Context ctx{std::filesystem::path(path).parent_path(), limits};
    Reader r(j, "scene");
    SceneDesc scene;
    scene.path = path;
    scene.gravity = r.vec3("gravity", scene.gravity);
    scene.dt = r.number("dt", scene.dt);
    scene.steps = r.intIn("steps", scene.steps, 0);
    if (r.has("solver")) scene.solver = parseSolver(r.required("solver", "an object"));
    if (r.has("bodies")) {
      const json& bodies = r.array("bodies", "an array of bodies");
      checkCount(r, "bodies", bodies, limits.bodies, "bodies");
      scene.bodies.reserve(bodies.size());
      for (size_t i = 0; i < bodies.size(); ++i) scene.bodies.push_back(parseBody(bodies[i], i, ctx));
    }
    const BodyNames names = bodyNames(scene);
    if (r.has("springs")) {
      const json& springs = r.array("springs", "an array of springs");
      checkCount(r, "springs", springs, limits.springs, "springs");
      for (size_t i = 0; i < springs.size(); ++i) {
        Reader s(springs[i], objectLabel("spring", springs[i], i));
        SpringDef d;
        d.name = s.name("name", "spring" + std::to_string(i));
        std::tie(d.body_a, d.body_b) = bodyPair(s, names);
        const json& a = s.required("anchors", "two world points [[x,y,z],[x,y,z]]");
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
      const json& joints = r.array("joints", "an array of joints");
      checkCount(r, "joints", joints, limits.joints, "joints");
      for (size_t i = 0; i < joints.size(); ++i) scene.joints.push_back(parseJoint(joints[i], i, names));
    }
    if (r.has("validation")) scene.validation_json = r.required("validation", "an object").dump();
    (void)r.string("description", "");
    r.finish();
    checkScene(scene, limits);
    validateScene(scene);
    return scene;
  } catch (const InputError& e) {
    const std::string obj = e.object().empty() ? path : path + ": " + e.object();
    throw InputError(obj, e.field(), e.message());
  }
}

SceneDesc loadScene(const std::string& path, const InputLimits& limits) {
  // Only a regular file: a directory, a FIFO or a device (/dev/zero) would
  // fail late or never end.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "", "not a regular file (or cannot be read)");
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > limits.file_bytes)
    throw InputError(path, "", std::to_string(bytes) + " bytes exceed the limit " + limitHint("file_bytes", limits.file_bytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open scene file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseScene(ss.str(), path, limits);
}

}  // namespace cairn
