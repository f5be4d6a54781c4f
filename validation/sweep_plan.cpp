#include "validation/sweep_plan.hpp"

#include "cairn/error.hpp"
#include "validation/solver_keys.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>

namespace cairn::validation {

namespace {

const std::vector<std::string> kAlwaysShown = {"method", "substeps", "iterations", "erp", "dt"};

// Settings that do not reach Bullet (docs/validation.md, "How settings
// map"): a Bullet job shows "bullet" for the method and "-" for the rest,
// and one Bullet run serves every value of them.
bool bulletIgnores(const std::string& key) { return key == "method" || key == "nncg"; }

int columnOf(const SweepPlan& plan, const std::string& key) {
  const auto it = std::find(plan.columns.begin(), plan.columns.end(), key);
  return it == plan.columns.end() ? -1 : int(it - plan.columns.begin());
}

}  // namespace

VaryAxis parseVary(const std::string& arg, const SceneDesc& scene) {
  const auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--vary", "", "expected KEY=V1,V2,... (got '" + arg + "')");
  VaryAxis axis;
  axis.key = arg.substr(0, eq);
  if (!isSolverKey(axis.key))
    throw InputError("--vary", "", "unknown setting '" + axis.key + "' (known: " + solverKeyList() + ")");
  const std::string list = arg.substr(eq + 1);
  std::vector<std::string> texts;
  for (size_t from = 0;;) {
    const size_t comma = list.find(',', from);
    texts.push_back(list.substr(from, comma == std::string::npos ? std::string::npos : comma - from));
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  // Parsed and checked on a copy of the scene, then stored as the text that
  // reads back to the same value ("1/60" -> 0.016666666666666666).
  const auto canonical = [&](const std::string& text) {
    if (text.empty()) throw InputError("--vary " + axis.key, "", "empty value in '" + arg + "'");
    SceneDesc probe = scene;
    setSolverKey(probe, axis.key, text, "--vary " + axis.key);
    return solverKeyValue(probe, axis.key);
  };
  for (size_t t = 0; t < texts.size(); ++t) {
    if (texts[t] != "...") {
      axis.values.push_back(canonical(texts[t]));
      continue;
    }
    // "a,b,...,z" or "a,b,c,...,z": the progression the values before it
    // start, continued below z, then z. Geometric when three values share
    // a ratio ("1,2,4,...,200": 8 to 128, then 200), else
    // arithmetic ("1,2,...,10", "0.1,0.2,...,0.6").
    if (axis.values.size() < 2 || t + 2 != texts.size())
      throw InputError("--vary " + axis.key, "",
                       "'...' needs two values before it and one after it, at the end (got '" + arg + "')");
    const std::string end_text = canonical(texts[t + 1]);
    const size_t n = axis.values.size();
    double a = 0, b = 0, z = 0, before = 0;
    try {
      a = std::stod(axis.values[n - 2]);
      b = std::stod(axis.values[n - 1]);
      z = std::stod(end_text);
      before = n >= 3 ? std::stod(axis.values[n - 3]) : 0;
    } catch (const std::exception&) {
      throw InputError("--vary " + axis.key, "", "'...' continues numbers only (got '" + arg + "')");
    }
    if (!(b > a) || !(z > b))
      throw InputError("--vary " + axis.key, "", "'...' needs increasing values before the end (got '" + arg + "')");
    const bool integral = axis.values.back().find_first_of(".eE") == std::string::npos;
    const auto same = [](double x, double y) { return std::abs(x - y) <= 1e-9 * std::max(std::abs(x), std::abs(y)); };
    const bool geometric = n >= 3 && before > 0 && same(b / a, a / before);
    if (n >= 3 && !geometric && !same(b - a, a - before))
      throw InputError("--vary " + axis.key, "", "the values before '...' are not a progression (got '" + arg + "')");
    for (int k = 1;; ++k) {
      const double next = geometric ? b * std::pow(b / a, k) : b + k * (b - a);
      if (!(next < z) || same(next, z)) break;
      char buf[64];
      std::snprintf(buf, sizeof buf, integral ? "%.0f" : "%.12g", integral ? std::round(next) : next);
      axis.values.push_back(canonical(buf));
      if (axis.values.size() > 10000) throw InputError("--vary " + axis.key, "", "'...' expands to over 10000 values");
    }
    axis.values.push_back(end_text);
    break;
  }
  for (size_t i = 0; i < axis.values.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (axis.values[i] == axis.values[k])
        throw InputError("--vary " + axis.key, "", "value '" + axis.values[i] + "' is listed twice");
  return axis;
}

SweepPlan makeSweepPlan(const std::vector<VaryAxis>& axes, const SceneDesc& scene) {
  SweepPlan plan;
  plan.axes = axes;
  for (size_t i = 0; i < axes.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (axes[i].key == axes[k].key) throw InputError("--vary " + axes[i].key, "", "this key is varied twice");
  for (const std::string& key : solverKeyNames()) {
    const bool varied = std::any_of(axes.begin(), axes.end(), [&](const VaryAxis& a) { return a.key == key; });
    if (varied || std::find(kAlwaysShown.begin(), kAlwaysShown.end(), key) != kAlwaysShown.end())
      plan.columns.push_back(key);
  }
  std::vector<std::string> base;
  for (const std::string& key : plan.columns) base.push_back(solverKeyValue(scene, key));

  // Cartesian product, first axis outermost: an odometer whose last digit
  // turns fastest.
  std::vector<size_t> digit(axes.size(), 0);
  while (true) {
    SweepJob job;
    job.index = int(plan.jobs.size());
    job.settings = base;
    for (size_t a = 0; a < axes.size(); ++a) job.settings[size_t(columnOf(plan, axes[a].key))] = axes[a].values[digit[a]];
    plan.jobs.push_back(job);
    size_t a = axes.size();
    while (a > 0 && ++digit[a - 1] == axes[a - 1].values.size()) digit[--a] = 0;
    if (a == 0) break;
  }
  plan.cairn_jobs = int(plan.jobs.size());

  for (int i = 0; i < plan.cairn_jobs; ++i) {
    SweepJob b = plan.jobs[size_t(i)];
    for (size_t c = 0; c < plan.columns.size(); ++c)
      if (bulletIgnores(plan.columns[c])) b.settings[c] = plan.columns[c] == "method" ? "bullet" : "-";
    b.bullet = true;
    const bool seen = std::any_of(plan.jobs.begin() + plan.cairn_jobs, plan.jobs.end(),
                                  [&](const SweepJob& j) { return j.settings == b.settings; });
    if (seen) continue;
    b.index = int(plan.jobs.size());
    plan.jobs.push_back(b);
  }
  return plan;
}

SceneDesc jobScene(const SweepPlan& plan, const SweepJob& job, const SceneDesc& base) {
  SceneDesc scene = base;
  for (size_t c = 0; c < plan.columns.size(); ++c) {
    const std::string& key = plan.columns[c];
    if (job.bullet && bulletIgnores(key)) continue;  // the scene keeps its value; Bullet does not read it
    setSolverKey(scene, key, job.settings[c], "--vary " + key);
  }
  if (scene.dt != base.dt) scene.steps = std::max(1, int(std::lround(base.steps * base.dt / scene.dt)));
  return scene;
}

int bulletJobFor(const SweepPlan& plan, const SweepJob& job) {
  for (int i = plan.cairn_jobs; i < int(plan.jobs.size()); ++i) {
    const SweepJob& b = plan.jobs[size_t(i)];
    bool same = true;
    for (size_t c = 0; c < plan.columns.size() && same; ++c)
      same = bulletIgnores(plan.columns[c]) || b.settings[c] == job.settings[c];
    if (same) return i;
  }
  return -1;
}

Shard parseShard(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return InputError("--shard", "", "expected i/n with 0 <= i < n (0-based, e.g. 0/3, 1/3, 2/3): " + why);
  };
  const auto slash = text.find('/');
  if (slash == std::string::npos) throw bad("no '/' in '" + text + "'");
  const auto integer = [&](const std::string& s) {
    int v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size()) throw bad("'" + s + "' is not an integer");
    return v;
  };
  Shard s;
  s.index = integer(text.substr(0, slash));
  s.count = integer(text.substr(slash + 1));
  if (s.count < 1) throw bad("n must be >= 1 (got '" + text + "')");
  if (s.index < 0 || s.index >= s.count) throw bad("i out of range (got '" + text + "')");
  return s;
}

}  // namespace cairn::validation
