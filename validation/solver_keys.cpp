#include "validation/solver_keys.hpp"

#include "validation/csv.hpp"

#include "cairn/error.hpp"
#include "world/world_access.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

namespace cairn::validation {

namespace {

enum class Type { Method, Correction, Int, Real, Bool };

struct Key {
  const char* name;
  Type type;
};

// The order of the sweep table's setting columns.
constexpr Key kKeys[] = {
    {"method", Type::Method},     {"substeps", Type::Int},      {"iterations", Type::Int},
    {"erp", Type::Real},          {"dt", Type::Real},           {"cfm", Type::Real},
    {"contact_erp", Type::Real},  {"sor", Type::Real},          {"tolerance", Type::Real},
    {"warm_start", Type::Bool},   {"warm_start_factor", Type::Real}, {"randomize_order", Type::Bool},
    {"split_impulse", Type::Bool}, {"slop", Type::Real},        {"nncg", Type::Bool},
    {"sleeping", Type::Bool},     {"geometric_stiffness", Type::Bool}, {"position_iterations", Type::Int},
    {"recycle_distance", Type::Real}, {"recycle_angle", Type::Real}, {"friction_directions", Type::Int},
    {"position_correction", Type::Correction}, {"prepare_contacts_each_substep", Type::Bool},
    {"patch_friction", Type::Bool},
};

const Key* findKey(const std::string& name) {
  for (const Key& k : kKeys)
    if (name == k.name) return &k;
  return nullptr;
}

}  // namespace

std::string solverKeyList() {
  std::string s;
  for (const Key& k : kKeys) s += std::string(s.empty() ? "" : ", ") + k.name;
  return s;
}

namespace {

[[noreturn]] void bad(const std::string& where, const std::string& value, const std::string& why) {
  throw InputError(where, "", "'" + value + "' " + why);
}

}  // namespace

const std::vector<std::string>& solverKeyNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Key& k : kKeys) n.emplace_back(k.name);
    return n;
  }();
  return names;
}

bool isSolverKey(const std::string& key) { return findKey(key) != nullptr; }

double parseNumberText(const std::string& option, const std::string& text) {
  const auto one = [&](std::string_view s) {
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size())
      throw InputError(option, "", "not a number: '" + text + "'");
    return v;
  };
  const std::string_view s(text);
  const auto slash = s.find('/');
  const double v = slash == std::string_view::npos ? one(s) : one(s.substr(0, slash)) / one(s.substr(slash + 1));
  if (!std::isfinite(v)) throw InputError(option, "", "must be finite (got '" + text + "')");
  return v;
}

std::string exactNumberText(double v) {
  std::string s;
  appendExactNumber(s, v);
  return s;
}

void setSolverKey(SceneDesc& scene, const std::string& key, const std::string& value, const std::string& option) {
  const Key* k = findKey(key);
  if (!k) throw InputError(option, "", "unknown setting '" + key + "' (known: " + solverKeyList() + ")");
  SolverSettings s = scene.solver;
  switch (k->type) {
    case Type::Method: {
      bool found = false;
      for (SolverMethod m : {SolverMethod::Auto, SolverMethod::PGS, SolverMethod::Direct, SolverMethod::LCP})
        if (value == solverMethodName(m)) {
          s.method = m;
          found = true;
        }
      if (!found) bad(option, value, "is not a method (auto, pgs, direct or lcp)");
      break;
    }
    case Type::Correction: {
      // The scene file's names (world/scene_json.cpp).
      if (value == "baumgarte") s.position_correction = Correction::VelocityBias;
      else if (value == "split") s.position_correction = Correction::PseudoVelocity;
      else if (value == "single_pass") s.position_correction = Correction::InRhs;
      else bad(option, value, "is not a position correction (baumgarte, split or single_pass)");
      break;
    }
    case Type::Int: {
      int v = 0;
      const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (value.empty() || ec != std::errc() || end != value.data() + value.size())
        bad(option, value, "is not an integer");
      if (key == "substeps") s.substeps = v;
      else if (key == "position_iterations") s.position_iterations = v;
      else if (key == "friction_directions") s.friction_directions = v;
      else s.iterations = v;
      break;
    }
    case Type::Bool: {
      bool v = false;
      if (value == "true" || value == "1") v = true;
      else if (value != "false" && value != "0") bad(option, value, "is not true, false, 1 or 0");
      if (key == "warm_start") s.warm_start = v;
      else if (key == "randomize_order") s.randomize_order = v;
      else if (key == "nncg") s.nncg = v;
      else if (key == "sleeping") s.sleeping = v;
      else if (key == "geometric_stiffness") s.geometric_stiffness = v;
      else if (key == "prepare_contacts_each_substep") s.prepare_contacts_each_substep = v;
      else if (key == "patch_friction") s.patch_friction = v;
      else s.split_impulse = v;
      break;
    }
    case Type::Real: {
      double v = 0;
      v = parseNumberText(option, value);
      if (key == "dt") {
        if (v <= 0) bad(option, value, "must be a positive time step (s)");
        scene.dt = v;
        return;
      }
      if (key == "erp") s.erp = v;
      else if (key == "cfm") s.cfm = v;
      else if (key == "contact_erp") s.contact_erp = v;
      else if (key == "sor") s.sor = v;
      else if (key == "tolerance") s.tolerance = v;
      else if (key == "warm_start_factor") s.warm_start_factor = v;
      else if (key == "recycle_distance") s.recycle_distance = v;
      else if (key == "recycle_angle") s.recycle_angle = v;
      else s.slop = v;
      break;
    }
  }
  try {
    validateSettings(s);  // the World's own rules: ranges, >= 1 counts
  } catch (const InputError& e) {
    bad(option, value, "is out of range: " + e.message());
  }
  scene.solver = s;
}

std::string solverKeyValue(const SceneDesc& scene, const std::string& key) {
  const SolverSettings& s = scene.solver;
  if (key == "method") return solverMethodName(s.method);
  if (key == "substeps") return std::to_string(s.substeps);
  if (key == "iterations") return std::to_string(s.iterations);
  if (key == "erp") return exactNumberText(s.erp);
  if (key == "dt") return exactNumberText(scene.dt);
  if (key == "cfm") return exactNumberText(s.cfm);
  if (key == "contact_erp") return exactNumberText(s.contact_erp);
  if (key == "sor") return exactNumberText(s.sor);
  if (key == "tolerance") return exactNumberText(s.tolerance);
  if (key == "warm_start") return s.warm_start ? "true" : "false";
  if (key == "warm_start_factor") return exactNumberText(s.warm_start_factor);
  if (key == "randomize_order") return s.randomize_order ? "true" : "false";
  if (key == "split_impulse") return s.split_impulse ? "true" : "false";
  if (key == "slop") return exactNumberText(s.slop);
  if (key == "nncg") return s.nncg ? "true" : "false";
  if (key == "sleeping") return s.sleeping ? "true" : "false";
  if (key == "geometric_stiffness") return s.geometric_stiffness ? "true" : "false";
  if (key == "prepare_contacts_each_substep") return s.prepare_contacts_each_substep ? "true" : "false";
  if (key == "patch_friction") return s.patch_friction ? "true" : "false";
  if (key == "position_iterations") return std::to_string(s.position_iterations);
  if (key == "recycle_distance") return exactNumberText(s.recycle_distance);
  if (key == "recycle_angle") return exactNumberText(s.recycle_angle);
  if (key == "friction_directions") return std::to_string(s.friction_directions);
  if (key == "position_correction") {
    switch (s.position_correction) {
      case Correction::VelocityBias: return "baumgarte";
      case Correction::PseudoVelocity: return "split";
      case Correction::InRhs: return "single_pass";
    }
  }
  throw InputError("solver", key, "unknown setting");
}

}  // namespace cairn::validation
