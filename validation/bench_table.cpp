#include "validation/bench_table.hpp"

#include "cairn/error.hpp"
#include "validation/solver_keys.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace cairn::validation {

namespace {

namespace fs = std::filesystem;

// cairn's contact rows: a normal row and SolverSettings::friction_directions
// friction rows per point (2 unless set). Bullet's defaults solve one
// friction row per point along the sliding direction; matched adds the
// second (SOLVER_USE_2_FRICTION_DIRECTIONS, bullet_oracle.cpp).
int frictionDirections(BenchEngine e, const SolverSettings& s) {
  if (e == BenchEngine::Cairn) return s.friction_directions;
  return e == BenchEngine::BulletDefaults ? 1 : 2;
}

std::string num(double v) { return std::isfinite(v) ? exactNumberText(v) : std::string(); }
std::string num(const std::optional<double>& v) { return v ? num(*v) : std::string(); }

std::string g(const char* f, double v) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
std::string g(const char* f, const std::optional<double>& v) { return v ? g(f, *v) : "-"; }

struct Settings {
  std::string method, iterations, substeps, sleeping, friction, threads, overrides;
};

Settings settingsOf(const BenchScene& scene, BenchEngine e) {
  const SceneDesc& s = scene.scenes[size_t(e)];
  const SolverSettings& v = s.solver;
  Settings out;
  const bool cairn = e == BenchEngine::Cairn;
  out.method = cairn ? solverMethodName(v.method) : "pgs";  // btSequentialImpulseConstraintSolver
  out.iterations = std::to_string(v.iterations);
  out.substeps = std::to_string(v.substeps);
  if (scene.oracle[size_t(e)].bullet_deactivation)
    out.sleeping = "Bullet's: 0.8 m/s, 1 rad/s, 2 s";
  else
    out.sleeping = v.sleeping ? "on: " + g("%g", v.sleep_linear_velocity) + " m/s, " + g("%g", v.sleep_angular_velocity) +
                                    " rad/s, " + g("%g", v.sleep_time) + " s"
                              : "off";
  out.friction = std::to_string(frictionDirections(e, v));
  out.threads = cairn ? std::to_string(v.threads) : "1";  // btDiscreteDynamicsWorld steps on one thread
  out.overrides = scene.overrides[size_t(e)];
  return out;
}

// RFC 4180: a field with a comma, a quote or a line break is quoted, its
// quotes doubled.
std::string field(const std::string& s) {
  if (s.find_first_of(",\"\r\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csvLine(const std::vector<std::string>& cells) {
  std::string line;
  for (size_t i = 0; i < cells.size(); ++i) line += (i ? "," : "") + field(cells[i]);
  return line + "\r\n";
}

std::string mdLine(const std::vector<std::string>& cells) {
  std::string line = "|";
  for (const std::string& c : cells) line += " " + c + " |";
  return line + "\n";
}

// One character per column: 'l' text, 'r' a number.
std::string mdRule(const std::string& align) {
  std::string line = "|";
  for (char a : align) line += a == 'r' ? "---:|" : "---|";
  return line + "\n";
}

double ratio(const BenchSceneResult& r, BenchEngine e) {
  return r[e].medianMs() / r[BenchEngine::Cairn].medianMs();
}

// The value most scenes share, then the exceptions: "10 (ragdoll: 20)".
std::string acrossScenes(const std::vector<std::pair<std::string, std::string>>& by_scene) {
  std::map<std::string, int> count;
  for (const auto& [scene, value] : by_scene) ++count[value];
  std::string common;
  int best = 0;
  for (const auto& [value, n] : count)
    if (n > best) {
      best = n;
      common = value;
    }
  std::string out = common.empty() ? "-" : common;
  std::string except;
  for (const auto& [scene, value] : by_scene)
    if (value != common) except += (except.empty() ? "" : "; ") + scene + ": " + (value.empty() ? "-" : value);
  return except.empty() ? out : out + " (" + except + ")";
}

std::string escapeMd(std::string s) {
  for (size_t at = 0; (at = s.find('|', at)) != std::string::npos; at += 2) s.replace(at, 1, "\\|");
  return s;
}

}  // namespace

std::vector<std::string> benchCsvColumns() {
  std::vector<std::string> c = {"scene",      "family",     "engine",   "status",   "bodies",
                                "joints",     "steps",      "dt",       "method",   "iterations",
                                "substeps",   "sleeping",   "friction_directions", "threads", "overrides",
                                "repeats",    "ms_per_step", "ms_per_step_repeats", "ratio_vs_cairn",
                                "rows",       "contacts",   "contact_points", "sleeping_bodies_end",
                                "rest_from",  "rest_displacement_m", "penetration_m", "joint_error_m",
                                "exact_distance_m"};
  for (int k = 0; k < kStageCount; ++k) c.push_back(std::string("stage_") + stageName(static_cast<Stage>(k)) + "_ms");
  return c;
}

std::string benchCsv(const BenchTable& t) {
  std::string out = csvLine(benchCsvColumns());
  for (size_t i = 0; i < t.results.size(); ++i) {
    const BenchSceneResult& r = t.results[i];
    const BenchScene& scene = t.scenes[i];
    for (int k = 0; k < kBenchEngineCount; ++k) {
      const BenchEngine e = benchEngine(k);
      const BenchEngineResult& x = r[e];
      const Settings s = settingsOf(scene, e);
      const bool cairn = e == BenchEngine::Cairn;
      std::string runs;
      for (double ms : x.ms_per_step) runs += (runs.empty() ? "" : ";") + num(ms);
      std::vector<std::string> row = {r.name,
                                      r.family,
                                      benchEngineName(e),
                                      x.status,
                                      std::to_string(r.bodies),
                                      std::to_string(r.joints),
                                      std::to_string(scene.scenes[size_t(e)].steps),
                                      num(scene.scenes[size_t(e)].dt),
                                      s.method,
                                      s.iterations,
                                      s.substeps,
                                      s.sleeping,
                                      s.friction,
                                      s.threads,
                                      s.overrides,
                                      std::to_string(x.ms_per_step.size()),
                                      num(x.medianMs()),
                                      runs,
                                      num(ratio(r, e)),
                                      cairn ? num(x.rows) : "",
                                      cairn ? num(x.contacts) : "",
                                      cairn ? num(x.contact_points) : "",
                                      std::to_string(x.sleeping_bodies),
                                      restFromName(r.rest_from),
                                      num(x.rest_displacement),
                                      num(x.penetration),
                                      num(x.joint_error),
                                      num(x.exact_distance)};
      const auto stages = x.medianStageMs();
      for (int st = 0; st < kStageCount; ++st) row.push_back(cairn ? num(stages[size_t(st)]) : "");
      out += csvLine(row);
    }
  }
  return out;
}

std::string benchMarkdown(const BenchTable& t) {
  const auto& m = t.manifest;
  std::string md = "# cairn bench\n\n";
  md += "Command: `" + m.value("command", std::string()) + "`\n\n";
  md += "Date: " + m.value("date", std::string()) + "; machine: " + std::to_string(m["machine"].value("cpus", 0)) +
        " logical CPUs (`nproc`), " + m["machine"].value("cpu_model", std::string()) + "; load average " +
        m["machine"].value("load_start", std::string()) + " at the start, " +
        m["machine"].value("load_end", std::string()) + " at the end (1, 5, 15 min).\n\n";
  // The core check (validation/machine.hpp, coreShare): a manifest written
  // before it existed has none.
  const int probe = m["machine"].value("core_check_threads", 0);
  if (probe >= 2)
    md += "Core check: " + std::to_string(probe) + " threads running a multiply-add loop at once each kept " +
          g("%.2f", m["machine"].value("core_share_start", 0.0)) + " of one thread's rate at the start, " +
          g("%.2f", m["machine"].value("core_share_end", 0.0)) +
          " at the end (about 1 where the logical CPUs are cores of their own; well below, they shared cores with "
          "other work, and times on more than one thread say little about the engine).\n\n";
  md += "Repeats: " + std::to_string(m.value("repeats", 0)) +
        " per engine configuration, the three taking turns; a time is the median over repeats of a run's mean step "
        "time. Absolute times on a shared machine are noise: read the ratios, measured in the same run. "
        "Ratio = Bullet / cairn: above 1, cairn is faster.\n\n";

  md += "## Time (ms per step)\n\n";
  md += mdLine({"scene", "bodies", "rows", "contacts", "cairn", "Bullet defaults", "Bullet matched",
                "defaults / cairn", "matched / cairn"});
  md += mdRule("lrrrrrrrr");
  for (const BenchSceneResult& r : t.results) {
    const BenchEngineResult& c = r[BenchEngine::Cairn];
    md += mdLine({r.name, std::to_string(r.bodies), g("%.0f", c.rows), g("%.0f", c.contacts), g("%.3g", c.medianMs()),
                  g("%.3g", r[BenchEngine::BulletDefaults].medianMs()), g("%.3g", r[BenchEngine::BulletMatched].medianMs()),
                  g("%.2f", ratio(r, BenchEngine::BulletDefaults)), g("%.2f", ratio(r, BenchEngine::BulletMatched))});
  }

  md += "\n## Accuracy beside time\n\n";
  md += "Rest displacement: the largest distance a body that should rest moved, from its start pose (stacks) or "
        "over the last second (scenes dropped to settle). Penetration: deepest overlap over the last second. Joint "
        "error: largest anchor separation over the run. Exact distance: largest distance from cairn's exact "
        "bilateral solve of the same scene (method direct), where the scene has one. All in m, measured by the "
        "same code for every engine.\n\n";
  md += mdLine({"scene", "engine", "ms/step", "rest displacement", "from", "penetration", "joint error",
                "exact distance", "asleep at end", "status"});
  md += mdRule("llrrlrrrrl");
  for (const BenchSceneResult& r : t.results)
    for (int k = 0; k < kBenchEngineCount; ++k) {
      const BenchEngineResult& x = r.engines[size_t(k)];
      md += mdLine({r.name, benchEngineName(benchEngine(k)), g("%.3g", x.medianMs()), g("%.3g", x.rest_displacement),
                    restFromName(r.rest_from), g("%.3g", x.penetration), g("%.3g", x.joint_error),
                    g("%.3g", x.exact_distance), std::to_string(x.sleeping_bodies) + " / " + std::to_string(r.bodies),
                    escapeMd(x.status)});
    }
  for (const BenchSceneResult& r : t.results)
    if (!r.exact_note.empty()) md += "\n" + r.name + ": " + r.exact_note + "\n";

  md += "\n## Where cairn's step goes (median ms per step)\n\n";
  std::vector<std::string> head = {"scene"};
  for (int k = 0; k < kStageCount; ++k) head.emplace_back(stageName(static_cast<Stage>(k)));
  head.emplace_back("sum");
  md += mdLine(head) + mdRule("l" + std::string(head.size() - 1, 'r'));
  for (const BenchSceneResult& r : t.results) {
    const auto stages = r[BenchEngine::Cairn].medianStageMs();
    std::vector<std::string> row = {r.name};
    double sum = 0;
    for (double v : stages) {
      row.push_back(g("%.3g", v));
      sum += v;
    }
    row.push_back(g("%.3g", sum));
    md += mdLine(row);
  }

  md += "\n## Settings of each column\n\n";
  md += "Bullet is 3.24 in double precision (btDiscreteDynamicsWorld, btSequentialImpulseConstraintSolver). "
        "Bullet defaults: btContactSolverInfo's defaults but for the scene's iterations and step "
        "(OracleOptions{match_cairn = false, bullet_deactivation = true}). Bullet matched: cairn's model mapped "
        "onto Bullet (match_cairn = true). docs/benchmarks.md lists every choice.\n\n";
  md += mdLine({"column", "method", "iterations", "substeps", "sleeping", "friction directions per point", "threads",
                "overrides"});
  md += mdRule("llrrllrl");
  for (int k = 0; k < kBenchEngineCount; ++k) {
    const BenchEngine e = benchEngine(k);
    std::vector<std::pair<std::string, std::string>> method, iterations, substeps, sleeping, friction, threads, overrides;
    for (const BenchScene& scene : t.scenes) {
      const Settings s = settingsOf(scene, e);
      method.emplace_back(scene.name, s.method);
      iterations.emplace_back(scene.name, s.iterations);
      substeps.emplace_back(scene.name, s.substeps);
      sleeping.emplace_back(scene.name, s.sleeping);
      friction.emplace_back(scene.name, s.friction);
      threads.emplace_back(scene.name, s.threads);
      overrides.emplace_back(scene.name, s.overrides);
    }
    md += mdLine({benchEngineName(e), acrossScenes(method), acrossScenes(iterations), acrossScenes(substeps),
                  acrossScenes(sleeping), acrossScenes(friction), acrossScenes(threads), escapeMd(acrossScenes(overrides))});
  }

  for (int k = 0; k < kBenchEngineCount; ++k) {
    std::set<std::string> notes;
    for (const BenchSceneResult& r : t.results)
      for (const std::string& n : r.engines[size_t(k)].notes) notes.insert(n);
    if (notes.empty()) continue;
    if (benchEngine(k) == BenchEngine::Cairn)
      md += "\ncairn's steps on fewer threads than the table says (its worker threads were losing their cores to other work, and those steps ran on one thread):\n\n";
    else
      md += std::string("\nWhat ") + benchEngineName(benchEngine(k)) + " maps only approximately or not at all "
            "(BulletOracle::skipped, all scenes):\n\n";
    for (const std::string& n : notes) md += "- " + n + "\n";
  }
  return md;
}

void writeBenchFiles(const std::string& dir, const BenchTable& table) {
  const auto write = [&](const std::string& name, const std::string& content) {
    const fs::path p = fs::path(dir) / name;
    std::ofstream f(p, std::ios::binary);
    if (!f || !(f << content) || !f.flush()) throw InputError(p.string(), "", "cannot write benchmark file");
  };
  write("bench.csv", benchCsv(table));
  write("bench.md", benchMarkdown(table));
  write("bench.json", table.manifest.dump(1) + "\n");
}

}  // namespace cairn::validation
