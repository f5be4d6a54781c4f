// `cairn run` as a process under bad input and awkward output paths: each
// case ends with a documented exit status (2 for bad input, never a signal
// or another status), one message naming what is wrong, and either
// complete output files or none at all (no partial file, no temporary
// left behind). The trajectory CSV parses as RFC 4180 whatever the body
// names, the metrics hold numbers where numbers are documented, and a long
// run's trajectory is streamed, so peak memory does not grow with it.
#include "cli_test_helpers.hpp"
#include "validation/csv.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using cairn::test::CliResult;
using cairn::test::runCairn;
using cairn::test::slurp;
using cairn::test::TempDir;

const char* kScene = R"({
  "steps": 20, "dt": 0.015625,
  "bodies": [
    {"name": "ground", "type": "static", "shapes": [{"type": "plane", "normal": [0, 1, 0]}]},
    {"name": "a", "position": [0, 1, 0], "shapes": [{"type": "box", "half_extents": [0.5, 0.5, 0.5]}]},
    {"name": "b", "position": [3, 1, 0], "shapes": [{"type": "sphere", "radius": 0.5}]}
  ],
  "springs": [{"name": "s", "bodies": ["a", "b"], "anchors": [[0, 1, 0], [3, 1, 0]], "stiffness": 10}]
})";

std::string edited(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

std::string write(const TempDir& tmp, const std::string& name, const std::string& text) {
  std::ofstream(tmp / name, std::ios::binary) << text;
  return tmp / name;
}

// The names in `dir` other than the ones runCairn writes itself.
std::vector<std::string> filesIn(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n != "stdout.txt" && n != "stderr.txt") names.push_back(n);
  }
  std::sort(names.begin(), names.end());
  return names;
}

// A bad scene: status 2, one line on stderr naming the file, the object
// and the field, and no output file in the directory.
void expectRefused(const std::string& text, const std::string& message) {
  const TempDir tmp("cairn_run_bad");
  const std::string scene = write(tmp, "bad.json", text);
  const CliResult r = runCairn("run " + scene + " --steps 30 --out " + (tmp / "t.csv") + " --metrics " + (tmp / "m.json"), tmp);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(scene + ": " + message), std::string::npos) << "'" << message << "' missing in: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(filesIn(tmp.path), std::vector<std::string>{"bad.json"});
}

TEST(CliRun, MissingOrWrongTypedKeysExitTwoNamingFileObjectAndField) {
  expectRefused(edited(kScene, "\"half_extents\": [0.5, 0.5, 0.5]", "\"position\": [0, 0, 0]"),
                "body 'a': field 'shapes[0].half_extents': missing: an array of 3 numbers");
  expectRefused(edited(kScene, ", \"stiffness\": 10", ""), "spring 's': field 'stiffness': missing: a number");
  expectRefused(edited(kScene, "\"name\": \"b\",", "\"name\": \"b\", \"collision_mask\": null,"),
                "body 'b': field 'collision_mask': must be an integer in [0, 4294967295] (got null)");
  expectRefused(edited(kScene, "\"steps\": 20,", "\"solver\": {\"seed\": \"x\"},"),
                "solver: field 'seed': must be an integer in [0, 18446744073709551615] (got \"x\")");
  expectRefused(edited(kScene, "\"steps\": 20", "\"steps\": 4294967297"),
                "scene: field 'steps': must be an integer in [0, 2147483647] (got 4294967297)");
  expectRefused(edited(kScene, "\"position\": [3, 1, 0]", "\"position\": [3, 1, 0], \"angular_velocity\": [0, 1e300, 0]"),
                "body 'b': field 'angular_velocity': must have finite components with magnitude at most 1e+20");
}

// 100,000 nested arrays once overflowed the stack (a signal, no status);
// the parser now stops at the depth limit.
TEST(CliRun, DeeplyNestedInputExitsTwo) {
  const int deep = 100000;
  expectRefused(edited(kScene, "\"steps\": 20,", "\"validation\": " + std::string(deep, '[') + std::string(deep, ']') + ","),
                "arrays and objects nested more than 64 deep");
}

// The output paths are checked before the run: a directory, the same file
// twice, the scene itself, a place that takes no new file. Nothing is
// written, and nothing is left behind.
TEST(CliRun, BadOutputPathsExitTwoBeforeTheRunAndWriteNothing) {
  const TempDir tmp("cairn_run_out");
  const std::string scene = write(tmp, "s.json", kScene);
  fs::create_directories(tmp.path / "dir");
  const std::string t = tmp / "t.csv", m = tmp / "m.json";
  const std::pair<std::string, std::string> cases[] = {
      {"--out " + (tmp / "dir"), "--out: '" + (tmp / "dir") + "' is a directory"},
      {"--metrics " + (tmp / "dir"), "--metrics: '" + (tmp / "dir") + "' is a directory"},
      {"--out " + t + " --metrics " + t, "--metrics: '" + t + "' is also given to --out"},
      {"--out " + t + " --metrics " + (tmp / "dir") + "/../t.csv", "is also given to --out"},
      {"--out " + scene, "is an input of this run"},
      {"--out " + t + " --metrics " + (tmp / "missing") + "/m.json", "does not exist"},
      {"--out " + t + " --metrics /proc/m.json", "cannot write in '/proc'"},
  };
  for (const auto& [args, message] : cases) {
    const CliResult r = runCairn("run " + scene + " " + args, tmp);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": '" << message << "' missing in: " << r.err;
    EXPECT_EQ(r.out, "") << args;  // the run did not start
    EXPECT_EQ(filesIn(tmp.path), (std::vector<std::string>{"dir", "s.json"})) << args;
    EXPECT_TRUE(fs::is_empty(tmp.path / "dir")) << args;
  }
}

// A run that fails numerically (status 3) leaves the previous outputs as
// they were: the files are replaced only by a complete run. The scene is
// within every accepted range, but a spring of 1e20 N/m stretched over 1e20
// m doubles the bodies' speeds every step until they overflow (at step 11),
// which the NaN guard catches.
TEST(CliRun, FailedRunLeavesPreviousOutputsUntouched) {
  const TempDir tmp("cairn_run_fail");
  const std::string t = tmp / "t.csv", m = tmp / "m.json";
  std::ofstream(t) << "previous\n";
  std::string text = edited(kScene, "\"stiffness\": 10", "\"stiffness\": 1e20, \"rest_length\": 0");
  text = edited(edited(text, "\"position\": [3, 1, 0]", "\"position\": [1e20, 1, 0]"), "[3, 1, 0]]", "[1e20, 1, 0]]");
  const std::string scene = write(tmp, "s.json", text);
  const CliResult r = runCairn("run " + scene + " --out " + t + " --metrics " + m, tmp);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("non-finite state"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(t), "previous\n");
  EXPECT_EQ(filesIn(tmp.path), (std::vector<std::string>{"s.json", "t.csv"}));
}

// Body names holding commas and quotes are quoted (RFC 4180), so every
// record of the trajectory has the header's 16 fields and the names read
// back exactly.
TEST(CliRun, TrajectoryCsvParsesWhateverTheBodyNames) {
  const TempDir tmp("cairn_run_csv");
  std::string text = kScene;
  for (size_t at; (at = text.find("\"b\"")) != std::string::npos;) text.replace(at, 3, "\"b, \\\"the ball\\\"\"");
  const std::string scene = write(tmp, "s.json", text);
  const CliResult r = runCairn("run " + scene + " --out " + (tmp / "t.csv"), tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto records = cairn::validation::parseCsv(slurp(tmp / "t.csv"), "t.csv");
  ASSERT_EQ(records.size(), 1u + 21 * 2);  // header, steps 0..20 of two bodies
  for (const auto& rec : records) ASSERT_EQ(rec.size(), 16u);
  EXPECT_EQ(records[2][2], "b, \"the ball\"");
  EXPECT_EQ(records[2][0], "0");
}

// Every figure the metrics document as a number is a number (JSON has no
// infinity; a non-finite figure would be the string "inf" or "nan", never
// null): here for a scene at the edges of the accepted ranges, whose
// energies are ~1e59 J.
TEST(CliRun, MetricsHoldNoNull) {
  const TempDir tmp("cairn_run_metrics");
  const std::string scene =
      write(tmp, "s.json",
            edited(edited(kScene, "\"position\": [3, 1, 0]", "\"position\": [3, 1, 0], \"linear_velocity\": [1e20, 0, 0]"),
                   "\"name\": \"b\",", "\"name\": \"b\", \"density\": 1e20,"));
  const CliResult r = runCairn("run " + scene + " --metrics " + (tmp / "m.json"), tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto m = nlohmann::json::parse(slurp(tmp / "m.json"));
  std::vector<const nlohmann::json*> todo{&m};
  while (!todo.empty()) {
    const nlohmann::json* j = todo.back();
    todo.pop_back();
    EXPECT_FALSE(j->is_null()) << m.dump(1);
    if (j->is_structured())
      for (const auto& child : *j) todo.push_back(&child);
  }
  EXPECT_TRUE(m["energy_initial"].is_number());
  EXPECT_GT(m["energy_initial"].get<double>(), 1e59);  // 1/2 m v^2 with m ~ 5e19 kg, v = 1e20 m/s
  EXPECT_TRUE(m["energy_final"].is_number());
}

// Energy is recorded through the run, at most 1,000 samples whatever its
// length. A 1 kg ball falling freely under symplectic Euler (v += h g, then
// x += h v) loses exactly m g^2 h^2 / 2 per step:
//   dE = m g h v1 - m g h (v1 + v0) / 2 = m g h (v1 - v0) / 2 = -m g^2 h^2 / 2,
// so sample k (step k * every) is E0 - k every m g^2 h^2 / 2. The tolerance,
// 1e-4 J, is a relative 1e-9 of the kinetic and potential energies, which
// reach 7e4 J: round-off of 2,500 steps (about 1e-13 relative) with room.
TEST(CliRun, EnergyIsRecordedThroughTheRun) {
  const TempDir tmp("cairn_run_energy");
  const std::string scene = write(tmp, "fall.json", R"({
    "steps": 2500, "dt": 0.015625,
    "bodies": [{"name": "ball", "mass": 1, "shapes": [{"type": "sphere", "radius": 0.5}]}]
  })");
  const CliResult r = runCairn("run " + scene + " --metrics " + (tmp / "m.json"), tmp);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");  // nothing to diagnose in a free fall
  const auto m = nlohmann::json::parse(slurp(tmp / "m.json"));
  const int every = m["energy_every"].get<int>();
  EXPECT_EQ(every, 3);  // ceil(2500 / 1000)
  ASSERT_EQ(m["energy"].size(), 833u);  // steps 3, 6, ..., 2499
  const double e0 = m["energy_initial"].get<double>(), h = 0.015625, g = 9.81;
  for (size_t k = 0; k < m["energy"].size(); ++k) {
    const double want = e0 - double((k + 1) * every) * g * g * h * h / 2;
    ASSERT_NEAR(m["energy"][k].get<double>(), want, 1e-9 * 1e5) << "sample " << k;
  }
  EXPECT_NEAR(m["energy_max"].get<double>(), e0 - g * g * h * h / 2, 1e-6);
  EXPECT_NEAR(m["energy_min"].get<double>(), e0 - 2500 * g * g * h * h / 2, 1e-4);
}

// Peak resident memory of `cairn ARGS` run from the source directory (the
// child's own high-water mark, from wait4).
long peakKib(const std::string& args, int& status) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(CAIRN_SOURCE_DIR) != 0) ::_exit(127);
    std::vector<std::string> words{CAIRN_CLI};
    std::istringstream in(args);
    for (std::string w; in >> w;) words.push_back(w);
    std::vector<char*> argv;
    for (auto& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    ::freopen("/dev/null", "w", stdout);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  int raw = 0;
  struct rusage ru {};
  ::wait4(pid, &raw, 0, &ru);
  status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return ru.ru_maxrss;  // KiB on Linux
}

// 100,000 steps of 100 bodies, every step written: 10 million rows, 470 MB
// of CSV, which the command once held in memory until the end (peak 890
// MB). Streamed, the peak is that of the program, its libraries and the
// world, 9 MB measured (docs/reliability.md); the bound of 64 MiB leaves
// room for allocator slack and a larger binary, and is a seventh of the
// trajectory alone: anything that kept the rows would exceed it.
TEST(CliRun, LongTrajectoryIsStreamedWithFlatPeakMemory) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer keeps up to 256 MB of freed memory resident (its quarantine)";
#endif
  const TempDir tmp("cairn_run_memory");
  std::string bodies;
  for (int i = 0; i < 100; ++i)
    bodies += std::string(i ? ", " : "") + "{\"name\": \"b" + std::to_string(i) + "\", \"position\": [" +
              std::to_string(3 * (i % 10)) + ", 0, " + std::to_string(3 * (i / 10)) +
              "], \"shapes\": [{\"type\": \"sphere\", \"radius\": 0.5}]}";
  const std::string scene = write(tmp, "s.json", "{\"gravity\": [0, 0, 0], \"dt\": 0.015625, \"bodies\": [" + bodies + "]}");
  int status = 0;
  const long kib = peakKib("run " + scene + " --steps 100000 --out " + (tmp / "t.csv"), status);
  ASSERT_EQ(status, 0);
  const auto bytes = fs::file_size(tmp / "t.csv");
  EXPECT_GT(bytes, 100u * 100001u * 40u);  // every row is there: at least 40 bytes each
  EXPECT_LT(kib, 64 * 1024) << "peak " << kib << " KiB for a " << bytes / (1 << 20) << " MiB trajectory";
}

}  // namespace
