#include "validation/scene_writer.hpp"

#include "cairn/error.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace cairn::validation {

using Json = nlohmann::ordered_json;

namespace {

Json vec(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }
// Normalised as the reader normalises, so that a file read and written again
// comes out the same to the last digit.
Json quat(const Quat& q_in) {
  const Quat q = q_in.normalized();
  return Json::array({q.w(), q.x(), q.y(), q.z()});
}

Json mat(const Mat3& m) {
  Json rows = Json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(Json::array({m(r, 0), m(r, 1), m(r, 2)}));
  return rows;
}

bool isIdentity(const Quat& q) { return q.w() == 1 && q.x() == 0 && q.y() == 0 && q.z() == 0; }

const char* gyroscopicName(Gyroscopic g) {
  switch (g) {
    case Gyroscopic::Off: return "off";
    case Gyroscopic::Explicit: return "explicit";
    case Gyroscopic::ImplicitEuler: return "implicit_euler";
    case Gyroscopic::ImplicitMidpoint: return "implicit_midpoint";
  }
  return "implicit_midpoint";
}

const char* correctionName(Correction c) {
  switch (c) {
    case Correction::VelocityBias: return "baumgarte";
    case Correction::PseudoVelocity: return "split";
    case Correction::InRhs: return "single_pass";
  }
  return "baumgarte";
}

Json solverJson(const SolverSettings& s) {
  Json j;
  j["method"] = solverMethodName(s.method);
  j["iterations"] = s.iterations;
  j["position_iterations"] = s.position_iterations;
  j["geometric_stiffness"] = s.geometric_stiffness;
  j["tolerance"] = s.tolerance;
  j["sor"] = s.sor;
  j["warm_start"] = s.warm_start;
  j["warm_start_factor"] = s.warm_start_factor;
  j["randomize_order"] = s.randomize_order;
  j["nncg"] = s.nncg;
  j["seed"] = s.seed;
  j["substeps"] = s.substeps;
  j["erp"] = s.erp;
  j["cfm"] = s.cfm;
  j["position_correction"] = correctionName(s.position_correction);
  j["contact_erp"] = s.contact_erp;
  j["slop"] = s.slop;
  j["restitution_threshold"] = s.restitution_threshold;
  j["split_impulse"] = s.split_impulse;
  j["max_correction_velocity"] = s.max_correction_velocity;
  j["contact_margin"] = s.contact_margin;
  j["sleeping"] = s.sleeping;
  j["sleep_linear_velocity"] = s.sleep_linear_velocity;
  j["sleep_angular_velocity"] = s.sleep_angular_velocity;
  j["sleep_time"] = s.sleep_time;
  if (std::isfinite(s.max_angular_velocity)) j["max_angular_velocity"] = s.max_angular_velocity;
  j["gyroscopic"] = gyroscopicName(s.gyroscopic);
  j["orientation"] = s.orientation == OrientationIntegrator::ExponentialMap ? "exponential_map" : "derivative";
  return j;
}

Json shapeJson(const ShapeDesc& s) {
  Json j;
  j["type"] = shapeTypeName(s.type);
  switch (s.type) {
    case ShapeType::Sphere: j["radius"] = s.radius; break;
    case ShapeType::Box: j["half_extents"] = vec(s.half_extents); break;
    case ShapeType::Capsule:
    case ShapeType::Cylinder:
      j["radius"] = s.radius;
      j["half_height"] = s.half_height;
      break;
    case ShapeType::Plane:
      j["normal"] = vec(s.normal);
      j["offset"] = s.offset;
      break;
    case ShapeType::ConvexHull: {
      Json pts = Json::array();
      if (s.hull)
        for (const Vec3& p : s.hull->vertices) pts.push_back(vec(p));
      j["points"] = pts;
      break;
    }
    case ShapeType::Mesh: j["obj"] = s.source; break;
  }
  if (s.local.p != Vec3::Zero()) j["position"] = vec(s.local.p);
  if (!isIdentity(s.local.q)) j["orientation"] = quat(s.local.q);
  return j;
}

Json bodyJson(const BodyDef& b) {
  const BodyDef def;
  Json j;
  j["name"] = b.name;
  if (b.type != BodyType::Dynamic) j["type"] = bodyTypeName(b.type);
  if (b.mass) j["mass"] = *b.mass;
  if (b.density) j["density"] = *b.density;
  if (b.inertia) j["inertia"] = mat(*b.inertia);
  j["position"] = vec(b.position);
  if (!isIdentity(b.orientation)) j["orientation"] = quat(b.orientation);
  if (b.linear_velocity != Vec3::Zero()) j["linear_velocity"] = vec(b.linear_velocity);
  if (b.angular_velocity != Vec3::Zero()) j["angular_velocity"] = vec(b.angular_velocity);
  j["friction"] = b.friction;
  if (b.restitution != def.restitution) j["restitution"] = b.restitution;
  if (b.rolling_friction != def.rolling_friction) j["rolling_friction"] = b.rolling_friction;
  if (b.torsional_friction != def.torsional_friction) j["torsional_friction"] = b.torsional_friction;
  if (b.linear_damping != def.linear_damping) j["linear_damping"] = b.linear_damping;
  if (b.angular_damping != def.angular_damping) j["angular_damping"] = b.angular_damping;
  if (b.ccd) j["ccd"] = true;
  if (b.collision_group != def.collision_group) j["collision_group"] = b.collision_group;
  if (b.collision_mask != def.collision_mask) j["collision_mask"] = b.collision_mask;
  Json shapes = Json::array();
  for (const ShapeDesc& s : b.shapes) shapes.push_back(shapeJson(s));
  j["shapes"] = shapes;
  if (b.force != Vec3::Zero()) j["force"] = vec(b.force);
  if (b.torque != Vec3::Zero()) j["torque"] = vec(b.torque);
  if (!b.impulses.empty()) {
    Json imps = Json::array();
    for (const BodyDef::TimedImpulse& imp : b.impulses) {
      Json i;
      i["time"] = imp.time;
      i["impulse"] = vec(imp.impulse);
      if (imp.point) i["point"] = vec(*imp.point);
      imps.push_back(i);
    }
    j["impulses"] = imps;
  }
  const auto axes = [](const std::vector<Vec3>& list) {
    Json a = Json::array();
    for (const Vec3& v : list) a.push_back(vec(v));
    return a;
  };
  if (!b.lock_translation.empty()) j["lock_translation"] = axes(b.lock_translation);
  if (!b.lock_rotation.empty()) j["lock_rotation"] = axes(b.lock_rotation);
  return j;
}

std::string bodyName(const SceneDesc& scene, BodyId id) {
  return id.isWorld() ? std::string("world") : scene.bodies.at(static_cast<size_t>(id.index)).name;
}

void putSoftness(Json& j, const Softness& s) {
  if (s.erp) j["erp"] = *s.erp;
  if (s.cfm) j["cfm"] = *s.cfm;
  if (s.stiffness) j["stiffness"] = *s.stiffness;
  if (s.damping) j["damping"] = *s.damping;
  if (s.frequency) j["frequency"] = *s.frequency;
  if (s.damping_ratio) j["damping_ratio"] = *s.damping_ratio;
}

Json limitJson(const LimitDef& l) {
  Json j;
  j["lower"] = l.lower;
  j["upper"] = l.upper;
  if (l.restitution != 0) j["restitution"] = l.restitution;
  putSoftness(j, l.softness);
  return j;
}

Json motorJson(const MotorDef& m) {
  Json j;
  j["enabled"] = m.enabled;
  if (m.target_position) j["target_position"] = *m.target_position;
  else j["target_velocity"] = m.target_velocity;
  if (m.max_force) j["max_force"] = *m.max_force;
  putSoftness(j, m.softness);
  return j;
}

Json dofJson(const DofDef& d) {
  Json j;
  j["mode"] = dofModeName(d.mode);
  if (d.mode == DofMode::Limited) j["limits"] = limitJson(d.limit);
  if (d.spring.enabled) {
    Json s;
    s["rest"] = d.spring.rest;
    putSoftness(s, d.spring.softness);
    j["spring"] = s;
  }
  if (d.motor.enabled) j["motor"] = motorJson(d.motor);
  return j;
}

Json jointJson(const SceneDesc& scene, const JointDef& d) {
  const JointDef def;
  Json j;
  j["name"] = d.name;
  j["type"] = jointTypeName(d.type);
  j["bodies"] = Json::array({bodyName(scene, d.body_a), bodyName(scene, d.body_b)});
  if (d.type == JointType::Distance) {
    j["anchors"] = Json::array({vec(d.anchor_a), vec(d.anchor_b)});
    if (d.length) j["length"] = *d.length;
  } else {
    j["anchor"] = vec(d.anchor);
  }
  if (d.axis != def.axis) j["axis"] = vec(d.axis);
  if (d.axis2 != def.axis2) j["axis2"] = vec(d.axis2);
  if (d.limit.enabled) j["limits"] = limitJson(d.limit);
  if (d.swing_span1 != def.swing_span1) j["swing_span1"] = d.swing_span1;
  if (d.swing_span2 != def.swing_span2) j["swing_span2"] = d.swing_span2;
  if (d.type == JointType::AngularMotor) {
    if (!d.motor_axes.empty()) {
      Json m = Json::array();
      for (size_t i = 0; i < d.motor_axes.size(); ++i)
        m.push_back(Json{{"axis", vec(d.motor_axes[i])},
                         {"target_velocity", i < d.motor_targets.size() ? d.motor_targets[i] : Real(0)},
                         {"max_force", i < d.motor_max_torques.size() ? d.motor_max_torques[i] : Real(0)}});
      j["motor"] = m;
    }
  } else if (d.motor.enabled || d.motor.target_velocity != 0 || d.motor.max_force || d.motor.target_position) {
    j["motor"] = motorJson(d.motor);
  }
  if (d.type == JointType::SixDof) {
    Json dofs;
    for (int i = 0; i < kDofCount; ++i) dofs[dofName(i)] = dofJson(d.dofs[static_cast<size_t>(i)]);
    j["dofs"] = dofs;
  }
  putSoftness(j, d.softness);
  if (std::isfinite(d.break_force)) j["break_force"] = d.break_force;
  if (std::isfinite(d.break_torque)) j["break_torque"] = d.break_torque;
  if (d.collide_connected) j["collide_connected"] = true;
  return j;
}

Json springJson(const SceneDesc& scene, const SpringDef& d) {
  Json j;
  j["name"] = d.name;
  j["bodies"] = Json::array({bodyName(scene, d.body_a), bodyName(scene, d.body_b)});
  j["anchors"] = Json::array({vec(d.anchor_a), vec(d.anchor_b)});
  if (d.rest_length) j["rest_length"] = *d.rest_length;
  j["stiffness"] = d.stiffness;
  if (d.damping != 0) j["damping"] = d.damping;
  return j;
}

// The validation block with its keys in a fixed order (the reader keeps it
// as sorted JSON, so a block written as read must come out the same): the
// keys people look for first, the rest sorted, recursively.
Json normalized(const nlohmann::json& j) {
  static const char* first[] = {"type", "kind", "scenario", "body", "quantity", "tolerances", "top_body", "traces"};
  if (j.is_array()) {
    Json a = Json::array();
    for (const auto& e : j) a.push_back(normalized(e));
    return a;
  }
  if (!j.is_object()) return Json(j);
  Json o = Json::object();
  for (const char* k : first)
    if (j.contains(k)) o[k] = normalized(j[k]);
  for (auto it = j.begin(); it != j.end(); ++it)  // nlohmann::json iterates in sorted order
    if (!o.contains(it.key())) o[it.key()] = normalized(it.value());
  return o;
}

// Indented JSON with arrays of numbers or strings kept on one line.
void pretty(std::string& out, const Json& j, int indent) {
  const auto flat = [](const Json& a) {
    return std::all_of(a.begin(), a.end(), [](const Json& e) { return !e.is_structured(); });
  };
  const std::string pad(size_t(indent + 2), ' ');
  if (j.is_object() && !j.empty()) {
    out += "{";
    bool firstKey = true;
    for (auto it = j.begin(); it != j.end(); ++it) {
      out += firstKey ? "\n" : ",\n";
      firstKey = false;
      out += pad + Json(it.key()).dump() + ": ";
      pretty(out, it.value(), indent + 2);
    }
    out += "\n" + std::string(size_t(indent), ' ') + "}";
  } else if (j.is_array() && !j.empty() && !flat(j)) {
    out += "[";
    for (size_t i = 0; i < j.size(); ++i) {
      out += i == 0 ? "\n" : ",\n";
      out += pad;
      pretty(out, j[i], indent + 2);
    }
    out += "\n" + std::string(size_t(indent), ' ') + "]";
  } else {
    out += j.dump();
  }
}

// `"key": [item,\n item, ...]` with one compact item per line.
void putArrayOfLines(std::string& out, const char* key, const Json& items) {
  out += "  \"";
  out += key;
  out += "\": [";
  for (size_t i = 0; i < items.size(); ++i) {
    out += i == 0 ? "\n    " : ",\n    ";
    out += items[i].dump();
  }
  out += items.empty() ? "]" : "\n  ]";
}

}  // namespace

Json sceneToJson(const SceneDesc& scene, const std::string& description) {
  Json j;
  if (!description.empty()) j["description"] = description;
  j["gravity"] = vec(scene.gravity);
  j["dt"] = scene.dt;
  j["steps"] = scene.steps;
  j["solver"] = solverJson(scene.solver);
  Json bodies = Json::array();
  for (const BodyDef& b : scene.bodies) bodies.push_back(bodyJson(b));
  j["bodies"] = bodies;
  if (!scene.springs.empty()) {
    Json springs = Json::array();
    for (const SpringDef& s : scene.springs) springs.push_back(springJson(scene, s));
    j["springs"] = springs;
  }
  if (!scene.joints.empty()) {
    Json joints = Json::array();
    for (const JointDef& d : scene.joints) joints.push_back(jointJson(scene, d));
    j["joints"] = joints;
  }
  if (!scene.validation_json.empty()) j["validation"] = normalized(nlohmann::json::parse(scene.validation_json));
  return j;
}

std::string sceneToText(const SceneDesc& scene, const std::string& description) {
  const Json j = sceneToJson(scene, description);
  std::string out = "{";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    out += first ? "\n" : ",\n";
    first = false;
    const std::string& key = it.key();
    if (key == "bodies" || key == "springs" || key == "joints") {
      putArrayOfLines(out, key.c_str(), it.value());
    } else if (it.value().is_object()) {
      // Nested blocks (solver, validation) indented under their key.
      out += "  \"" + key + "\": ";
      pretty(out, it.value(), 2);
    } else {
      out += "  \"" + key + "\": " + it.value().dump();
    }
  }
  out += "\n}\n";
  return out;
}

void writeScene(const std::string& path, const SceneDesc& scene, const std::string& description) {
  const std::string text = sceneToText(scene, description);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw InputError(path, "", "cannot write scene file");
    f << text;
    if (!f) throw InputError(path, "", "cannot write scene file");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(path, "", "cannot write scene file");
  }
}

}  // namespace cairn::validation
