// `cairn bench`: the command's contract through the binary (CAIRN_CLI) --
// exit status, the documented bench.csv, ratios that are the ratios of the
// medians, accuracy columns that are figures, a resting column within the
// slop plus the correction's steady excess, bad input refused with nothing
// written -- and the configurations it compares: Bullet's defaults
// deactivate a resting stack, the matched Bullet and cairn do not, and
// every engine repeats its figures bit for bit. No speed is asserted. Runs
// are tens of steps to keep the suite fast.
#include "cli_test_helpers.hpp"
#include "cairn/error.hpp"
#include "solver/worker_pool.hpp"
#include "validation/bench_plan.hpp"
#include "validation/compare.hpp"
#include "validation/scenarios.hpp"
#include "validation/standard_scenes.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>
#include <vector>

namespace cairn {
namespace {

namespace fs = std::filesystem;

using test::CliResult;
using test::slurp;
using test::TempDir;

CliResult cairn(const std::string& args, const TempDir& tmp) { return test::runCairn(args, tmp); }

// An RFC 4180 reader written apart from the writer, so that the test reads
// the file as a spreadsheet would: fields split at commas outside quotes,
// "" inside quotes is one quote, records end with CRLF (a bare LF is
// accepted too).
std::vector<std::vector<std::string>> parseRfc4180(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  bool quoted = false, in_quotes = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_quotes) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        in_quotes = false;
      } else {
        field += c;
      }
    } else if (c == '"' && field.empty() && !quoted) {
      in_quotes = quoted = true;
    } else if (c == ',') {
      record.push_back(field);
      field.clear();
      quoted = false;
    } else if (c == '\r' || c == '\n') {
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      record.push_back(field);
      records.push_back(record);
      record.clear();
      field.clear();
      quoted = false;
    } else {
      field += c;
    }
  }
  EXPECT_FALSE(in_quotes) << "unterminated quoted field";
  if (!field.empty() || !record.empty()) {
    record.push_back(field);
    records.push_back(record);
  }
  return records;
}

using Row = std::map<std::string, std::string>;

// The columns docs/benchmarks.md documents, in order.
std::vector<std::string> documentedColumns() {
  std::vector<std::string> c = {"scene", "family", "engine", "status", "bodies", "joints", "steps", "dt", "method",
                                "iterations", "substeps", "sleeping", "friction_directions", "threads", "overrides",
                                "repeats", "ms_per_step", "ms_per_step_repeats", "ratio_vs_cairn", "rows", "contacts",
                                "contact_points", "sleeping_bodies_end", "rest_from", "rest_displacement_m",
                                "penetration_m", "joint_error_m", "exact_distance_m"};
  for (const char* s : {"forces", "collide", "islands", "build_rows", "solve", "integrate", "store", "events", "sleep",
                        "guards"})
    c.push_back(std::string("stage_") + s + "_ms");
  return c;
}

std::vector<Row> readBenchCsv(const std::string& path) {
  const auto records = parseRfc4180(slurp(path));
  EXPECT_FALSE(records.empty());
  if (records.empty()) return {};
  EXPECT_EQ(records[0], documentedColumns());
  std::vector<Row> rows;
  for (size_t i = 1; i < records.size(); ++i) {
    EXPECT_EQ(records[i].size(), records[0].size()) << "record " << i;
    Row r;
    for (size_t k = 0; k < records[0].size() && k < records[i].size(); ++k) r[records[0][k]] = records[i][k];
    rows.push_back(r);
  }
  return rows;
}

double num(const Row& r, const std::string& column) { return std::stod(r.at(column)); }

const Row& rowOf(const std::vector<Row>& rows, const std::string& scene, const std::string& engine) {
  for (const Row& r : rows)
    if (r.at("scene") == scene && r.at("engine") == engine) return r;
  throw std::runtime_error("no row " + scene + " / " + engine);
}

const char* const kEngines[] = {"cairn", "bullet_defaults", "bullet_matched"};

TEST(BenchCommand, ShortRunOfTwoSmallScenesWritesTheDocumentedTable) {
  TempDir tmp("cairn_bench");
  const std::string out = tmp / "out";
  const CliResult r = cairn("bench column-10 chain-20 --repeat 1 --steps 60 --out " + out, tmp);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  for (const char* f : {"bench.csv", "bench.md", "bench.json"}) EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  const std::vector<Row> rows = readBenchCsv(out + "/bench.csv");
  ASSERT_EQ(rows.size(), 6u);  // 2 scenes x 3 engine configurations

  // Every documented column is named in docs/benchmarks.md.
  const std::string doc = slurp(std::string(CAIRN_SOURCE_DIR) + "/docs/benchmarks.md");
  for (const std::string& c : documentedColumns()) EXPECT_NE(doc.find("`" + c + "`"), std::string::npos) << c;

  // The core check: each thread's share of one thread's multiply-add rate,
  // at the start and the end. A share is a ratio of two timings, so the
  // test bounds only what does not depend on timing: it is a finite number
  // above 0 (0 would mean a thread never ran). How far above 1 it may read
  // depends on what else shares the cores during the one-thread reference
  // (under `ctest -j2` another test can: 1.6 was seen), and timings are
  // measured, never asserted.
  const auto manifest = nlohmann::json::parse(slurp(out + "/bench.json"));
  const auto& machine = manifest.at("machine");
  EXPECT_EQ(machine.at("core_check_threads").get<int>(), std::min(2, std::max(1, machine.at("cpus").get<int>())));
  for (const char* k : {"core_share_start", "core_share_end"}) {
    EXPECT_TRUE(std::isfinite(machine.at(k).get<double>())) << k;
    EXPECT_GT(machine.at(k).get<double>(), 0) << k;
  }
  const std::string md = slurp(out + "/bench.md");
  if (machine.at("cpus").get<int>() >= 2) {
    EXPECT_NE(md.find("Core check: 2 threads"), std::string::npos);
  }

  for (const Row& row : rows) {
    SCOPED_TRACE(row.at("scene") + " " + row.at("engine"));
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("steps"), "60");
    EXPECT_EQ(row.at("repeats"), "1");
    EXPECT_GT(num(row, "ms_per_step"), 0);
    // The figures each scene has: penetration where bodies touch, joint
    // error and the exact distance where there are joints; each a finite
    // length, never negative.
    const bool column = row.at("scene") == "column-10";
    for (const std::string c : {"rest_displacement_m", "penetration_m", "joint_error_m", "exact_distance_m"}) {
      const bool expected = column ? (c == "rest_displacement_m" || c == "penetration_m")
                                   : (c == "joint_error_m" || c == "exact_distance_m");
      ASSERT_EQ(!row.at(c).empty(), expected) << c;
      if (!expected) continue;
      EXPECT_TRUE(std::isfinite(num(row, c))) << c;
      EXPECT_GE(num(row, c), 0) << c;
    }
    EXPECT_EQ(row.at("rest_from"), column ? "start" : "");
    const bool cairn_row = row.at("engine") == "cairn";
    EXPECT_EQ(row.at("threads"), "1");
    EXPECT_EQ(row.at("friction_directions"), row.at("engine") == "bullet_defaults" ? "1" : "2");
    EXPECT_EQ(row.at("sleeping"), row.at("engine") == "bullet_defaults" ? "Bullet's: 0.8 m/s, 1 rad/s, 2 s" : "off");
    EXPECT_EQ(row.at("stage_solve_ms").empty(), !cairn_row);
    if (cairn_row) {
      EXPECT_GT(num(row, "rows"), 0);  // the column's contacts, the chain's joints
      double stages = 0;
      for (const char* s : {"forces", "collide", "islands", "build_rows", "solve", "integrate", "store", "events",
                            "sleep", "guards"})
        stages += num(row, std::string("stage_") + s + "_ms");
      // The stages tile the step (one clock read per boundary); the run's
      // time is measured around World::step, which adds only the call.
      EXPECT_LE(stages, num(row, "ms_per_step") * 1.0001);
    }
  }

  // A resting column: the boxes start touching and stay, so the deepest
  // overlap is the steady one. Each contact is pushed out by the fraction
  // ERP of its depth beyond the slop per step, while a velocity solve that
  // fails to stop a box lets it sink at most g h^2 more per step (the
  // approach speed g h one step of gravity gives, for one step h); the
  // excess settles at most at g h^2 / ERP (13.6 mm at h = 1/60 s, ERP 0.2).
  // cairn and the matched Bullet allow slop = 5 mm; Bullet's defaults none
  // (m_linearSlop 0), with the same contact ERP (m_erp2 = 0.2).
  const SceneDesc col = validation::standardScene("column-10").scene;
  const double h = col.dt, g = 9.81, erp = col.solver.contact_erp;
  for (const char* e : kEngines) {
    const double slop = std::string(e) == "bullet_defaults" ? 0 : col.solver.slop;
    EXPECT_LE(num(rowOf(rows, "column-10", e), "penetration_m"), slop + g * h * h / erp) << e;
  }
}

TEST(BenchCommand, RatiosAreTheRatiosOfTheMediansAndRepeatsAgreeBitForBit) {
  TempDir tmp("cairn_bench");
  const std::string out = tmp / "out";
  const CliResult r = cairn("bench column-10 chain-20 --repeat 3 --steps 20 --out " + out, tmp);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::vector<Row> rows = readBenchCsv(out + "/bench.csv");
  ASSERT_EQ(rows.size(), 6u);
  for (const Row& row : rows) {
    SCOPED_TRACE(row.at("scene") + " " + row.at("engine"));
    // "ok": the second and third repeats gave the first one's figures
    // exactly (bench_run.cpp compares them), so both engines are deterministic.
    EXPECT_EQ(row.at("status"), "ok");
    std::vector<double> runs;
    std::string list = row.at("ms_per_step_repeats");
    for (size_t from = 0; from <= list.size();) {
      const size_t at = std::min(list.find(';', from), list.size());
      runs.push_back(std::stod(list.substr(from, at - from)));
      from = at + 1;
    }
    ASSERT_EQ(runs.size(), 3u);
    std::sort(runs.begin(), runs.end());
    EXPECT_EQ(num(row, "ms_per_step"), runs[1]);  // the median of three, read back exactly
    const double cairn_ms = num(rowOf(rows, row.at("scene"), "cairn"), "ms_per_step");
    // Both numbers are printed to round-trip, so the only difference is the
    // division's rounding (half an ulp).
    EXPECT_NEAR(num(row, "ratio_vs_cairn"), num(row, "ms_per_step") / cairn_ms, 1e-15 * num(row, "ratio_vs_cairn"));
  }
}

TEST(BenchCommand, BadInputExitsTwoAndWritesNothing) {
  TempDir tmp("cairn_bench");
  const std::string out = tmp / "never";
  struct Case {
    std::string args, names;
  };
  const std::vector<Case> cases = {
      {"bench no-such-scene --steps 5", "no-such-scene"},
      {"bench column-10 --repeat 0", "--repeat"},
      {"bench column-10 --steps 0", "--steps"},
      {"bench column-10 --threads 0", "--threads"},
      {"bench column-10 --set iterations=0", "--set iterations"},
      {"bench column-10 --set bogus=1", "bogus"},
      {"bench column-10 --cairn-set dt=0.01", "--cairn-set"},
      {"bench column-10 --scaling", "--scaling"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const CliResult r = cairn(c.args + " --out " + out, tmp);
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_NE(r.err.find(c.names), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // An --out that cannot be a directory: a path under a regular file.
  const std::string file = tmp / "a_file";
  { std::ofstream(file) << "x"; }
  const CliResult r = cairn("bench column-10 --steps 5 --out " + file + "/sub", tmp);
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(file + "/sub"));
  EXPECT_EQ(slurp(file), "x");
}

// The two Bullet configurations differ where the bench says they do:
// Bullet's own deactivation (0.8 m/s, 1 rad/s, 2 s) puts a resting stack to
// sleep once it has been still for 2 s, while the matched Bullet follows
// the scene (sleeping off) and so does cairn; an explicit sleeping=false
// keeps Bullet's defaults awake too.
TEST(BenchRun, BulletDefaultsDeactivateARestingStackWhereTheSceneDoesNot) {
  SceneDesc scene = validation::standardScene("column-3").scene;
  scene.steps = 180;  // 3 s: past Bullet's 2 s
  validation::BenchOverrides o;
  const validation::BenchSceneResult r = validation::runBenchScene(validation::makeBenchScene("column-3", scene, o), 1);
  EXPECT_EQ(r[validation::BenchEngine::BulletDefaults].sleeping_bodies, 3);
  EXPECT_EQ(r[validation::BenchEngine::BulletMatched].sleeping_bodies, 0);
  EXPECT_EQ(r[validation::BenchEngine::Cairn].sleeping_bodies, 0);

  o.bullet = {"sleeping=false"};
  const validation::BenchSceneResult awake =
      validation::runBenchScene(validation::makeBenchScene("column-3", scene, o), 1);
  EXPECT_EQ(awake[validation::BenchEngine::BulletDefaults].sleeping_bodies, 0);
}

// A time taken on fewer threads than the table's column says must show.
// Which steps a busy machine's scheduler takes a core from is its own
// doing, so the lost cores are simulated (WorkerPool::simulateLostCores:
// every step on the pool is found sharing): by the watch's rule
// (world/pool_watch.hpp) steps 1 and 18 run on the pool and the other 28
// of 30 alone, and the bench says so per scene and repeat. (That a real
// shared core is found: WorkerPool.AWaitForAThreadOnTheSameCoreIsCounted-
// AsPreempted and the pinned-core determinism test.)
TEST(BenchRun, StepsOnFewerThreadsThanAskedAreNoted) {
  SceneDesc scene = validation::standardScene("pyramid-20").scene;
  scene.steps = 30;
  validation::BenchOverrides o;
  o.threads = 2;
  struct LostCores {
    LostCores() { WorkerPool::simulateLostCores(true); }
    ~LostCores() { WorkerPool::simulateLostCores(false); }
  };
  validation::BenchSceneResult r;
  {
    const LostCores lost;
    r = validation::runBenchScene(validation::makeBenchScene("pyramid-20", scene, o), 1);
  }
  const std::vector<std::string>& notes = r[validation::BenchEngine::Cairn].notes;
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0],
            "pyramid-20, repeat 1: 28 of 30 steps on one thread, not 2: the worker threads were losing their cores "
            "to other work (StepStats::threads)");
}

// The bench measures with `cairn validate`'s rulers: on the same scene its
// cairn and matched-Bullet figures are validate's, bit for bit (a stack's
// drift and penetration, a chain's joint error and distance from the exact
// solve).
TEST(BenchRun, FiguresAreThoseCairnValidateReports) {
  for (const std::string key : {"column-10", "chain-20"}) {
    SCOPED_TRACE(key);
    SceneDesc scene = validation::standardScene(key).scene;
    scene.steps = 90;
    const validation::SceneResult v = validation::validateScene(scene, key, key, "");
    const validation::BenchSceneResult b =
        validation::runBenchScene(validation::makeBenchScene(key, scene, validation::BenchOverrides{}), 1);
    const auto figure = [&](const std::string& k) -> const validation::Figure& {
      for (const validation::Figure& f : v.figures)
        if (f.key == k) return f;
      throw std::runtime_error("no figure " + k);
    };
    const auto& c = b[validation::BenchEngine::Cairn];
    const auto& m = b[validation::BenchEngine::BulletMatched];
    if (key == "column-10") {
      EXPECT_EQ(c.rest_displacement, figure("drift").cairn);
      EXPECT_EQ(m.rest_displacement, figure("drift").bullet);
      EXPECT_EQ(c.penetration, figure("penetration").cairn);
      EXPECT_EQ(m.penetration, figure("penetration").bullet);
    } else {
      EXPECT_EQ(c.joint_error, figure("joint_error").cairn);
      EXPECT_EQ(m.joint_error, figure("joint_error").bullet);
      EXPECT_EQ(c.exact_distance, figure("reference_distance").cairn);
      EXPECT_EQ(m.exact_distance, figure("reference_distance").bullet);
    }
  }
}

// The bench hands the three configurations the machine in turns
// (bench_run.hpp); their worlds are independent, so the turns' length
// changes no figure of any configuration: turns of 7 steps (the last one
// short) against each run made in one piece, over two repeats (each
// starting its turns with another configuration).
TEST(BenchRun, TurnsChangeNoFigureOfAnyConfiguration) {
  for (const std::string key : {"column-10", "chain-20"}) {
    SCOPED_TRACE(key);
    SceneDesc scene = validation::standardScene(key).scene;
    scene.steps = 90;
    const validation::BenchScene bench = validation::makeBenchScene(key, scene, validation::BenchOverrides{});
    const validation::BenchSceneResult whole = validation::runBenchScene(bench, 2, {}, scene.steps);
    const validation::BenchSceneResult turns = validation::runBenchScene(bench, 2, {}, 7);
    for (int k = 0; k < validation::kBenchEngineCount; ++k) {
      const validation::BenchEngine e = validation::benchEngine(k);
      SCOPED_TRACE(validation::benchEngineName(e));
      const validation::BenchEngineResult& a = whole[e];
      const validation::BenchEngineResult& b = turns[e];
      EXPECT_EQ(b.status, "ok");
      EXPECT_EQ(a.status, b.status);
      EXPECT_EQ(a.steps, 90);
      EXPECT_EQ(a.steps, b.steps);
      EXPECT_EQ(a.ms_per_step.size(), b.ms_per_step.size());
      EXPECT_EQ(a.rows, b.rows);
      EXPECT_EQ(a.contacts, b.contacts);
      EXPECT_EQ(a.contact_points, b.contact_points);
      EXPECT_EQ(a.sleeping_bodies, b.sleeping_bodies);
      EXPECT_EQ(a.rest_displacement, b.rest_displacement);
      EXPECT_EQ(a.penetration, b.penetration);
      EXPECT_EQ(a.joint_error, b.joint_error);
      EXPECT_EQ(a.exact_distance, b.exact_distance);
    }
  }
}

TEST(BenchPlan, OverridesReachTheEnginesTheyName) {
  const SceneDesc scene = validation::standardScene("column-3").scene;
  validation::BenchOverrides o;
  o.all = {"substeps=2"};
  o.cairn = {"iterations=4"};
  o.bullet = {"iterations=20"};
  o.threads = 2;
  o.steps = 7;
  const validation::BenchScene b = validation::makeBenchScene("column-3", scene, o);
  const auto& c = b.scenes[size_t(validation::BenchEngine::Cairn)];
  EXPECT_EQ(c.solver.iterations, 4);
  EXPECT_EQ(c.solver.substeps, 2);
  EXPECT_EQ(c.solver.threads, 2);
  EXPECT_EQ(c.steps, 7);
  for (auto e : {validation::BenchEngine::BulletDefaults, validation::BenchEngine::BulletMatched}) {
    const auto& s = b.scenes[size_t(e)];
    EXPECT_EQ(s.solver.iterations, 20);
    EXPECT_EQ(s.solver.substeps, 2);
    EXPECT_EQ(s.solver.threads, 1);
  }
  EXPECT_EQ(b.overrides[size_t(validation::BenchEngine::Cairn)], "substeps=2 steps=7 iterations=4");
  // Bullet's defaults are Bullet as it ships (its deactivation too); the
  // matched Bullet is cairn's model.
  EXPECT_FALSE(b.oracle[size_t(validation::BenchEngine::BulletDefaults)].match_cairn);
  EXPECT_TRUE(b.oracle[size_t(validation::BenchEngine::BulletDefaults)].bullet_deactivation);
  EXPECT_TRUE(b.oracle[size_t(validation::BenchEngine::BulletMatched)].match_cairn);
  EXPECT_FALSE(b.oracle[size_t(validation::BenchEngine::BulletMatched)].bullet_deactivation);
  // A new dt keeps the simulated time: 1/120 s doubles the step count.
  validation::BenchOverrides fine;
  fine.all = {"dt=1/120"};
  EXPECT_EQ(validation::makeBenchScene("column-3", scene, fine).base.steps, 2 * scene.steps);
}

TEST(Scenarios, SizedKeysBuildTheScalingSeries) {
  // pile-N: a whole cube of boxes on the ground; pyramid-100: the large pyramid.
  EXPECT_EQ(scenarios::byName("pile-125").bodies.size(), 125u + 1);
  EXPECT_EQ(scenarios::byName("pile-8000").bodies.size(), 8000u + 1);
  EXPECT_EQ(scenarios::byName("pyramid-100").bodies.size(), 5050u + 1);
  EXPECT_EQ(scenarios::byName("chain-1000").joints.size(), 1000u);
  EXPECT_THROW(scenarios::byName("pile-100"), InputError);  // not a cube
  for (const validation::ListedScene& s : validation::scalingSeries()) {
    EXPECT_NO_THROW(validation::standardScene(s.key)) << s.key;
    EXPECT_GT(s.steps, 0);
  }
}

}  // namespace
}  // namespace cairn
