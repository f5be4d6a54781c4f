// The replay viewer's data (validation/replay*.hpp) and `cairn view`
// (docs/viewer.md): what the recorder reads from the World obeys the
// physics it shows (contact forces carry a resting box's weight, a hanging
// bob's joint force balances gravity, islands match the World's count), a
// CSV replays bit for bit what the run recorded, RFC 4180 quoting reads
// back, and bad input exits 2 naming the file and writing nothing. The
// page itself is tested in a browser (tests/browser/viewer_test.py).
#include "cli_test_helpers.hpp"
#include "cairn/error.hpp"
#include "validation/csv.hpp"
#include "validation/replay_csv.hpp"
#include "validation/replay_page.hpp"
#include "validation/replay_record.hpp"
#include "world/scene_json.hpp"
#include "cairn/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

namespace cairn {
namespace {

namespace fs = std::filesystem;
using test::CliResult;
using test::slurp;
using validation::Replay;

struct TempDir : test::TempDir {
  TempDir() : test::TempDir("cairn_view") {}
};

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// A 1 kg box resting on a static ground box, and a 2 kg box alone further
// along; sleeping off so both stay awake islands.
const char* kTwoIslands = R"({
  "dt": 0.016666666666666666, "steps": 60,
  "solver": {"sleeping": false, "iterations": 30},
  "bodies": [
    {"name": "ground", "type": "static", "position": [0, -0.5, 0], "shapes": [{"type": "box", "half_extents": [20, 0.5, 20]}]},
    {"name": "box", "mass": 1, "position": [0, 0.5, 0], "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]},
    {"name": "top", "mass": 1, "position": [0, 1.5, 0], "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]},
    {"name": "alone", "mass": 2, "position": [5, 0.5, 0], "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]}
  ]})";

Replay record(const SceneDesc& scene, World& world) {
  Replay r;
  validation::ReplayRecorder rec(world, scene.dt, r);
  for (int s = 0; s < scene.steps; ++s) {
    world.step(scene.dt);
    rec.record(world);
  }
  return r;
}

// Net contact force on body b at frame f, as the page sums it (picking.js).
Vec3 contactForce(const Replay& r, int b, int f) {
  const auto& o = r.overlays;
  Vec3 sum = Vec3::Zero();
  size_t p = o.point_begin[size_t(f)];
  for (size_t m = o.manifold_begin[size_t(f)]; m < o.manifold_begin[size_t(f) + 1]; ++m) {
    double normal = 0;
    for (int k = 0; k < o.manifold_points[m]; ++k) normal += o.point_impulse[p++];
    const double side = o.manifold_body[2 * m + 1] == b ? 1 : o.manifold_body[2 * m] == b ? -1 : 0;
    const Vec3 n(o.manifold_normal[3 * m], o.manifold_normal[3 * m + 1], o.manifold_normal[3 * m + 2]);
    const Vec3 t(o.manifold_friction[3 * m], o.manifold_friction[3 * m + 1], o.manifold_friction[3 * m + 2]);
    sum += side * (n * normal + t) * r.substeps / r.dt;
  }
  return sum;
}

TEST(ReplayRecord, ContactForcesOnRestingBoxesBalanceTheirWeight) {
  const SceneDesc scene = parseScene(kTwoIslands, "two-islands.json");
  World world = buildWorld(scene);
  const Replay r = record(scene, world);
  const int last = r.cairn.frames() - 1;
  // At rest, Newton's second law: the contact forces on each box sum to
  // its weight, upward ('box' is pushed up by the ground with both boxes'
  // weight and down by 'top' with one). 30 PGS sweeps on two stacked boxes
  // leave the impulses converged to well under 1%; float32 storage adds
  // 1e-7 relative.
  const double g = 9.81;
  EXPECT_NEAR(contactForce(r, 1, last).y(), 1 * g, 0.01 * g);
  EXPECT_NEAR(contactForce(r, 2, last).y(), 1 * g, 0.01 * g);
  EXPECT_NEAR(contactForce(r, 3, last).y(), 2 * g, 0.01 * 2 * g);
  EXPECT_NEAR(contactForce(r, 1, last).x(), 0, 0.01 * g);
}

TEST(ReplayRecord, IslandsMatchTheWorldsCountAndSplitAtStaticBodies) {
  const SceneDesc scene = parseScene(kTwoIslands, "two-islands.json");
  World world = buildWorld(scene);
  const Replay r = record(scene, world);
  const int last = r.cairn.frames() - 1;
  const size_t n = size_t(r.bodyCount());
  std::set<int> islands;
  for (size_t b = 0; b < n; ++b)
    if (r.overlays.island[size_t(last) * n + b] >= 0) islands.insert(r.overlays.island[size_t(last) * n + b]);
  EXPECT_EQ(int(islands.size()), world.lastStepStats().islands);  // the World's own count
  EXPECT_EQ(islands.size(), 2u);  // the stack and the lone box: the ground links nothing
  EXPECT_EQ(r.overlays.island[size_t(last) * n + 1], r.overlays.island[size_t(last) * n + 2]);
  EXPECT_EQ(r.overlays.island[size_t(last) * n + 0], -1);
}

TEST(ReplayRecord, HangingBobsJointForceBalancesGravityAndAnchorsAreTheErrorApart) {
  const SceneDesc scene = parseScene(R"({
    "dt": 0.016666666666666666, "steps": 30,
    "bodies": [{"name": "bob", "mass": 3, "position": [0, -1, 0], "shapes": [{"type": "sphere", "radius": 0.1}]}],
    "joints": [{"name": "pivot", "type": "ball", "bodies": ["world", "bob"], "anchor": [0, 0, 0]}]})",
                                     "bob.json");
  World world = buildWorld(scene);
  const Replay r = record(scene, world);
  const auto& o = r.overlays;
  for (int f = 1; f < r.cairn.frames(); ++f) {
    const size_t k = size_t(f);
    // Equilibrium of the bob hanging at rest: the joint pulls up with m g
    // (1e-6 relative: the ball joint's rows solve exactly at rest).
    EXPECT_NEAR(o.joint_force_b[3 * k + 1], 3 * 9.81, 3 * 9.81 * 1e-6) << "frame " << f;
    const Vec3 a(o.joint_anchor_a[3 * k], o.joint_anchor_a[3 * k + 1], o.joint_anchor_a[3 * k + 2]);
    const Vec3 b(o.joint_anchor_b[3 * k], o.joint_anchor_b[3 * k + 1], o.joint_anchor_b[3 * k + 2]);
    // A ball joint's linear error is its anchors' separation; float32 rounding of the anchors.
    EXPECT_NEAR((a - b).norm(), o.joint_error[2 * k], 1e-6) << "frame " << f;
  }
}

TEST(ReplayContacts, ThinningKeepsEveryKthFrameWithinTheBudget) {
  const SceneDesc scene = parseScene(kTwoIslands, "two-islands.json");
  World world = buildWorld(scene);
  Replay r = record(scene, world);
  const validation::ReplayOverlays full = r.overlays;
  const size_t per_frame = full.point_begin[2] - full.point_begin[1];
  ASSERT_GT(per_frame, 0u);
  const int k = validation::thinContacts(r.overlays, full.point_impulse.size() * 16 / 4);
  EXPECT_GE(k, 2);
  const auto& o = r.overlays;
  for (size_t f = 0; f < o.contact_frame.size(); ++f) {
    EXPECT_EQ(o.contact_frame[f], f - f % size_t(k));
    const size_t shown = o.contact_frame[f];
    // The kept frame's points are the original ones, in order.
    ASSERT_EQ(o.point_begin[shown + 1] - o.point_begin[shown], full.point_begin[shown + 1] - full.point_begin[shown]);
    EXPECT_EQ(o.point_impulse[o.point_begin[shown]], full.point_impulse[full.point_begin[shown]]);
  }
}

TEST(ReplayParting, FindsTheFirstFrameBeyondTheTolerance) {
  validation::ReplayTrack a, b;
  for (int f = 0; f < 5; ++f) {
    a.time.push_back(f * 0.1);
    b.time.push_back(f * 0.1);
    for (int body = 0; body < 2; ++body) {
      a.position.insert(a.position.end(), {0, float(f), 0});
      b.position.insert(b.position.end(), {body == 1 ? 0.03f * float(f) : 0.0f, float(f), 0});
    }
  }
  const auto p = validation::findParting(a, b, 2, 0.05);  // 0.03 f > 0.05 first at f = 2
  EXPECT_EQ(p.frame, 2);
  EXPECT_EQ(p.body, 1);
  EXPECT_NEAR(p.distance, 0.06, 1e-6);
  EXPECT_EQ(validation::findParting(a, b, 2, 1.0).frame, -1);
}

TEST(CsvRecords, ReadsRfc4180QuotedFields) {
  const auto rec = validation::parseCsvRows("a,\"b, \"\"c\"\"\",d\r\n\n\"multi\nline\",2\n", "x.csv");
  ASSERT_EQ(rec.size(), 2u);
  EXPECT_EQ(rec[0].fields, (std::vector<std::string>{"a", "b, \"c\"", "d"}));
  EXPECT_EQ(rec[1].fields, (std::vector<std::string>{"multi\nline", "2"}));
  EXPECT_EQ(rec[1].line, 3);
  EXPECT_THROW(validation::parseCsvRows("a,\"open\n", "x.csv"), InputError);
  EXPECT_THROW(validation::parseCsvRows("a,b\"c\n", "x.csv"), InputError);
}

// --------------------------------------------------------------- cairn view

const char* kQuotedScene = R"({"dt": 0.016666666666666666, "steps": 20,
  "bodies": [{"name": "ground", "type": "static", "shapes": [{"type": "plane", "normal": [0, 1, 0], "offset": 0}]},
             {"name": "box, \"one\"", "mass": 1, "position": [0, 2, 0], "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]},
             {"name": "ball", "mass": 1, "position": [2, 3, 0], "shapes": [{"type": "sphere", "radius": 0.5}]}]})";

TEST(CairnView, ReplaysARunCsvExactlyAsTheRunRecordedIt) {
  TempDir tmp;
  write(tmp / "s.json", kQuotedScene);
  ASSERT_EQ(test::runCairn("run " + tmp / "s.json" + " --out " + tmp / "run.csv", tmp).status, 0);
  // The same run recorded directly (determinism: the same World steps bit
  // for bit; both paths round the doubles to float32 the same way).
  const SceneDesc scene = loadScene(tmp / "s.json");
  World world = buildWorld(scene);
  const Replay direct = record(scene, world);
  std::string csv = slurp(tmp / "run.csv");
  // RFC 4180 quoting of the name, whether or not `cairn run` quotes it:
  // the unquoted form would split the row at the name's comma.
  const std::string plain = ",box, \"one\",", quoted = ",\"box, \"\"one\"\"\",";
  for (size_t at = csv.find(plain); at != std::string::npos; at = csv.find(plain, at + quoted.size()))
    csv.replace(at, plain.size(), quoted);
  Replay fromCsv = validation::describeScene(scene);
  validation::readRunCsv(csv, "run.csv", fromCsv);
  ASSERT_EQ(fromCsv.cairn.frames(), direct.cairn.frames());
  EXPECT_EQ(fromCsv.cairn.position, direct.cairn.position);
  EXPECT_EQ(fromCsv.cairn.velocity, direct.cairn.velocity);
  EXPECT_EQ(fromCsv.cairn.time, direct.cairn.time);
  for (size_t i = 0; i < direct.cairn.orientation.size(); ++i)
    EXPECT_NEAR(fromCsv.cairn.orientation[i], direct.cairn.orientation[i], 1e-7);  // renormalized on read
}

TEST(CairnView, WritesOneSelfContainedPageAndPrintsItsSize) {
  TempDir tmp;
  write(tmp / "s.json", kQuotedScene);
  const CliResult r = test::runCairn("view " + tmp / "s.json" + " --run --out " + tmp / "page.html", tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto bytes = fs::file_size(tmp / "page.html");
  EXPECT_NE(r.out.find("(" + std::to_string(bytes) + " bytes)"), std::string::npos) << r.out;
  const std::string html = slurp(tmp / "page.html");
  // Offline from file://: nothing is loaded from elsewhere.
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_NE(html.find("\"format\":\"cairn replay 1\""), std::string::npos);
  EXPECT_NE(html.find("WebGLRenderer"), std::string::npos);  // three.js is inlined
}

TEST(CairnView, WithoutCsvOrRunItRunsTheScene) {
  TempDir tmp;
  write(tmp / "s.json", kQuotedScene);
  const CliResult r = test::runCairn("view " + tmp / "s.json" + " --out " + tmp / "page.html", tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("no RUN.csv given: running"), std::string::npos);
  EXPECT_NE(r.out.find("21 frames"), std::string::npos) << r.out;  // 20 steps and the start
}

struct BadViewInput {
  const char* what;
  std::string csv;       // written to run.csv unless empty and absent is meant
  bool write_csv = true;
  std::string extra;     // more arguments
  std::string expected;  // in stderr
};

TEST(CairnView, BadInputExitsTwoNamingTheFileAndWritesNothing) {
  const std::string header = "step,time,body,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n";
  const std::string row_box = "0,0,\"box, \"\"one\"\"\",0,2,0,1,0,0,0,0,0,0,0,0,0\n";
  const std::string row_ball = "0,0,ball,2,3,0,1,0,0,0,0,0,0,0,0,0\n";
  const std::vector<BadViewInput> cases = {
      {"missing csv", "", false, "", "run.csv: no such file"},
      {"empty file", "", true, "", "run.csv: empty file"},
      {"header only", header, true, "", "run.csv: empty run"},
      {"other columns", "step,time,body,x,y,z\n0,0,ball,0,0,0\n", true, "", "run.csv: line 1: columns do not match"},
      {"unknown body", header + row_box + "0,0,crate,2,3,0,1,0,0,0,0,0,0,0,0,0\n", true, "",
       "run.csv: line 3: body 'crate' is not a moving body of the scene"},
      {"static body listed", header + "0,0,ground,0,0,0,1,0,0,0,0,0,0,0,0,0\n", true, "", "'ground' is not a moving body"},
      {"missing body", header + row_box + "1,0.1,\"box, \"\"one\"\"\",0,2,0,1,0,0,0,0,0,0,0,0,0\n", true, "",
       "line 3: body 'box, \"one\"' where the scene's order expects 'ball'"},
      {"short row", header + row_box + "0,0,ball,2,3\n", true, "", "line 3: 5 fields, expected 16"},
      {"not a number", header + row_box + "0,0,ball,2,x,0,1,0,0,0,0,0,0,0,0,0\n", true, "", "column 'py': 'x'"},
      {"steps go back", header + row_box + row_ball + row_box + row_ball, true, "", "steps must increase"},
      {"csv and --run", header + row_box + row_ball, true, "--run", "given with --run"},
  };
  for (const BadViewInput& c : cases) {
    TempDir tmp;
    write(tmp / "s.json", kQuotedScene);
    if (c.write_csv) write(tmp / "run.csv", c.csv);
    const CliResult r =
        test::runCairn("view " + tmp / "s.json" + " " + tmp / "run.csv" + " " + c.extra + " --out " + tmp / "page.html", tmp);
    EXPECT_EQ(r.status, 2) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.what << ": " << r.err;
    EXPECT_FALSE(fs::exists(tmp / "page.html")) << c.what;
    EXPECT_FALSE(fs::exists(tmp / "page.html.tmp")) << c.what;
  }
  // The scene itself: a missing file, and a run of no steps.
  TempDir tmp;
  CliResult r = test::runCairn("view " + tmp / "none.json" + " --out " + tmp / "page.html", tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("none.json: no such scene file"), std::string::npos) << r.err;
  write(tmp / "s.json", kQuotedScene);
  r = test::runCairn("view " + tmp / "s.json" + " --steps 0 --out " + tmp / "page.html", tmp);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--steps"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "page.html"));
}

TEST(CairnValidate, ReportLinksAReplayPageWithBulletPerScene) {
  TempDir tmp;
  const CliResult r = test::runCairn("validate hinge-pendulum-0.1 --steps 30 --report " + tmp / "rep", tmp);
  ASSERT_LE(r.status, 1) << r.err;
  const std::string md = slurp(tmp / "rep/report.md");
  EXPECT_NE(md.find("[hinge-pendulum-0.1.replay.html](hinge-pendulum-0.1.replay.html)"), std::string::npos);
  const std::string html = slurp(tmp / "rep/hinge-pendulum-0.1.replay.html");
  EXPECT_EQ(html.find("\"bullet\":null"), std::string::npos);  // Bullet's track is in the page
  EXPECT_NE(html.find("\"parting\":{\"tolerance\":0.01"), std::string::npos);  // the scene's position tolerance
}

}  // namespace
}  // namespace cairn
