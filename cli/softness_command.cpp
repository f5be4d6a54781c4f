// `cairn softness`: translate between the three softness spellings of
// constraints/softness.hpp, for users tuning ODE-style ERP/CFM.
//
//   cairn softness --erp E --cfm C --dt H [--mass M]
//       -> stiffness k = ERP / (h CFM), damping c = (1 - ERP) / CFM and, with
//          a mass, f = sqrt(k/m) / (2 pi), zeta = c / (2 sqrt(k m))
//   cairn softness --stiffness K --damping C --dt H [--mass M]
//       -> ERP = h k / (h k + c), CFM = 1 / (h k + c) (and f, zeta with a mass)
//   cairn softness --frequency F [--damping-ratio Z] --mass M --dt H
//       -> k = m (2 pi f)^2, c = 2 zeta m (2 pi f), then ERP and CFM
//
// Every form also prints CFM / h, the term cairn adds to the row's diagonal
// because its lambda is an impulse while ODE's CFM multiplies a force
// (constraints/row.hpp, docs/constraints.md). Each output line is
// `name = value unit  formula` with the scene-file field names, so a line
// can be pasted into a joint's "softness". Numbers may be written as a
// fraction ("--dt 1/60"). Bad input: one line on stderr, exit status 2.
#include "cli/commands.hpp"
#include "constraints/softness.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace cairn::cli {

namespace {

struct SoftnessOptions {
  std::optional<std::string> erp, cfm, stiffness, damping, frequency, damping_ratio, dt, mass;
};

struct BadInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A finite decimal number, or a fraction of two ("1/60").
double parseNumber(const std::string& flag, const std::string& text) {
  const auto one = [&](std::string_view s) {
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size())
      throw BadInput(flag + ": not a number: '" + text + "'");
    return v;
  };
  const std::string_view s(text);
  const auto slash = s.find('/');
  const double v = slash == std::string_view::npos ? one(s) : one(s.substr(0, slash)) / one(s.substr(slash + 1));
  if (!std::isfinite(v)) throw BadInput(flag + ": must be finite (got '" + text + "')");
  return v;
}

std::optional<double> read(const char* flag, const std::optional<std::string>& text) {
  if (!text) return std::nullopt;
  const double v = parseNumber(flag, *text);
  if (v < 0) throw BadInput(std::string(flag) + ": must be >= 0 (got " + *text + ")");
  return v;
}

std::string num(double v) {
  if (std::isinf(v)) return "inf";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return buf;
}

// `name = value unit` padded into columns, then the formula.
void line(std::string& out, const std::string& name, double v, const std::string& unit, const std::string& formula) {
  std::string s = name;
  s.resize(std::max<size_t>(s.size(), 14), ' ');
  s += "= " + num(v);
  if (!unit.empty()) s += " " + unit;
  s.resize(std::max<size_t>(s.size() + 2, 40), ' ');
  out += s + formula + "\n";
}

void printErpCfm(std::string& out, const ErpCfm& e, double h) {
  line(out, "erp", e.erp, "", "erp = h k / (h k + c)");
  line(out, "cfm", e.cfm, "m/(N s)", "cfm = 1 / (h k + c)");
  line(out, "cfm_over_h", e.cfm / h, "1/kg", "added to the row's diagonal: lambda is an impulse");
}

void printSpring(std::string& out, const SpringEquivalent& s, bool with_mass) {
  line(out, "stiffness", s.stiffness, "N/m", "k = erp / (h cfm)");
  line(out, "damping", s.damping, "N s/m", "c = (1 - erp) / cfm");
  if (!with_mass) return;
  line(out, "frequency", s.frequency, "Hz", "f = sqrt(k / m) / (2 pi)");
  line(out, "damping_ratio", s.damping_ratio, "", "zeta = c / (2 sqrt(k m))");
}

// Validates everything, then returns the whole report (nothing is printed
// on bad input).
std::string report(const SoftnessOptions& o) {
  const int spellings = (o.erp || o.cfm) + (o.stiffness || o.damping) + (o.frequency || o.damping_ratio);
  if (spellings > 1)
    throw BadInput("give one spelling: --erp/--cfm, --stiffness/--damping or --frequency/--damping-ratio, not a mix");
  if (spellings == 0)
    throw BadInput("give one spelling: --erp and --cfm, --stiffness/--damping, or --frequency/--damping-ratio");
  if (!o.dt) throw BadInput("--dt: the time step is required (ERP and CFM depend on it)");
  const double h = *read("--dt", o.dt);
  if (h <= 0) throw BadInput("--dt: must be > 0 (got " + *o.dt + ")");
  const std::optional<double> mass = read("--mass", o.mass);
  if (mass && *mass <= 0) throw BadInput("--mass: must be > 0 (got " + *o.mass + ")");

  ErpCfm e;
  std::string note;
  if (o.erp || o.cfm) {
    if (!o.erp || !o.cfm) throw BadInput(std::string(o.erp ? "--cfm" : "--erp") + ": give both --erp and --cfm");
    e = {*read("--erp", o.erp), *read("--cfm", o.cfm)};
    if (e.erp > 1) throw BadInput("--erp: must lie in [0, 1] (got " + *o.erp + ")");
    if (e.cfm == 0) note = "note: cfm = 0 is a rigid row (infinite stiffness)\n";
    if (!mass) note += "note: give --mass for the frequency and damping ratio\n";
  } else if (o.stiffness || o.damping) {
    const double k = read("--stiffness", o.stiffness).value_or(0), c = read("--damping", o.damping).value_or(0);
    if (h * k + c <= 0) throw BadInput("--stiffness: stiffness and damping are both zero: the row would do nothing");
    e = erpCfmFromSpring(k, c, h);
  } else {
    if (!o.frequency) throw BadInput("--damping-ratio: needs --frequency");
    if (!mass) throw BadInput("--mass: required with --frequency (k = m omega^2)");
    const double f = *read("--frequency", o.frequency);
    if (f <= 0) throw BadInput("--frequency: must be > 0 (got " + *o.frequency + ")");
    e = erpCfmFromFrequency(f, read("--damping-ratio", o.damping_ratio).value_or(1), *mass, h);
    if (!o.damping_ratio) note = "note: no --damping-ratio given: 1 (critical), as in a scene file\n";
  }
  std::string out = "h = " + num(h) + " s" + (mass ? ", m = " + num(*mass) + " kg" : std::string()) + "\n";
  printErpCfm(out, e, h);
  printSpring(out, springFromErpCfm(e.erp, e.cfm, h, mass.value_or(1)), mass.has_value());
  return out + note;
}

}  // namespace

void addSoftnessCommand(CLI::App& app, int& status) {
  auto opt = std::make_shared<SoftnessOptions>();
  CLI::App* cmd = app.add_subcommand(
      "softness",
      "Convert between ERP/CFM, stiffness/damping and frequency/damping ratio (constraints/softness.hpp).\n"
      "For an angular row read N/m as N m/rad and the mass as a moment of inertia (kg m^2).");
  cmd->add_option("--erp", opt->erp, "Error reduction parameter, in [0, 1]");
  cmd->add_option("--cfm", opt->cfm, "Constraint force mixing, ODE units (m/(N s)), >= 0");
  cmd->add_option("--stiffness", opt->stiffness, "Spring stiffness k (N/m)");
  cmd->add_option("--damping", opt->damping, "Damping c (N s/m)");
  cmd->add_option("--frequency", opt->frequency, "Natural frequency (Hz), with --mass");
  cmd->add_option("--damping-ratio", opt->damping_ratio, "Damping ratio (1 = critical; default 1)");
  cmd->add_option("--dt", opt->dt, "Time step h (s); a fraction like 1/60 is accepted");
  cmd->add_option("--mass", opt->mass, "Mass on the row (kg): the body's mass, or 1/(J M^-1 J^T)");
  cmd->callback([opt, &status] {
    try {
      std::cout << report(*opt);
      status = 0;
    } catch (const BadInput& e) {
      std::cerr << "cairn softness: " << e.what() << "\n";
      status = 2;
    }
  });
}

}  // namespace cairn::cli
