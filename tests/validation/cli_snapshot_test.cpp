// `cairn run --save-state FILE` and `cairn run --restore FILE`: a run split
// in two through a snapshot writes the same trajectory rows, to the last
// digit, as the run made in one go (the CSV's numbers are shortest
// round-trip decimals, so equal text is equal bits); bad snapshots exit 2
// with the snapshot named.
#include "cli_test_helpers.hpp"

#include <gtest/gtest.h>

#include <sstream>

namespace cairn {
namespace {

using test::runCairn;
using test::TempDir;

// The CSV rows of steps >= from (the header dropped).
std::string rowsFrom(const std::string& csv, int from) {
  std::istringstream in(csv);
  std::string line, out;
  std::getline(in, line);
  while (std::getline(in, line))
    if (std::stoi(line.substr(0, line.find(','))) >= from) out += line + "\n";
  return out;
}

TEST(CliSnapshot, RunSplitBySaveStateAndRestoreEqualsTheStraightRun) {
  TempDir tmp("cairn_cli_snapshot");
  ASSERT_EQ(runCairn("run scenes/ragdoll.json --steps 120 --out " + tmp / "straight.csv", tmp).status, 0);
  const auto first = runCairn("run scenes/ragdoll.json --steps 60 --save-state " + tmp / "s.snap", tmp);
  ASSERT_EQ(first.status, 0) << first.err;
  const auto second = runCairn("run --restore " + tmp / "s.snap" + " --steps 60 --out " + tmp / "rest.csv", tmp);
  ASSERT_EQ(second.status, 0) << second.err;
  const std::string straight = rowsFrom(test::slurp(tmp.path / "straight.csv"), 60);
  ASSERT_FALSE(straight.empty());
  EXPECT_EQ(rowsFrom(test::slurp(tmp.path / "rest.csv"), 60), straight);
}

TEST(CliSnapshot, BadSnapshotOrMissingStepsExitsTwoNamingTheProblem) {
  TempDir tmp("cairn_cli_snapshot_bad");
  {
    std::ofstream f(tmp / "junk.snap");
    f << "not a snapshot";
  }
  const auto junk = runCairn("run --restore " + tmp / "junk.snap" + " --steps 5", tmp);
  EXPECT_EQ(junk.status, 2);
  EXPECT_NE(junk.err.find("not a cairn snapshot"), std::string::npos) << junk.err;
  const auto no_steps = runCairn("run --restore " + tmp / "junk.snap", tmp);
  EXPECT_EQ(no_steps.status, 2);
  EXPECT_NE(no_steps.err.find("--steps"), std::string::npos) << no_steps.err;
  const auto both = runCairn("run scenes/ragdoll.json --restore " + tmp / "junk.snap" + " --steps 5", tmp);
  EXPECT_EQ(both.status, 2);
}

}  // namespace
}  // namespace cairn
