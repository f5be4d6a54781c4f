// cairn_bench: Google Benchmark timings (bench/pgs_bench.cpp), plus the
// measurement tables docs/constraints.md quotes, printed as Markdown:
//
//   cairn_bench [--benchmark_* flags]        timings
//   cairn_bench --table chain-whip           chain-20 whip: cairn and Bullet vs iterations
//   cairn_bench --table correction           position-correction modes compared
//   cairn_bench --table mass-ratio           hinge limit on a small box on a long arm
//   cairn_bench --table extremes [NAME]      the extremes suite: cairn default, best, Bullet
//   cairn_bench --table extremes-variants NAME  every setting the suite tried on those cases
//   cairn_bench --table extremes-default [NAME]  default settings only: holds? reported? by what
//
// The tables measure physics, not time, so they are deterministic.
#include <benchmark/benchmark.h>

#include <cstring>
#include <iostream>
#include <string>

namespace cairn::bench {
int chainWhipTable();
int correctionTable();
int massRatioTable();
int extremesTable(const std::string& filter);
int extremesVariantsTable(const std::string& filter);
int extremesDefaultTable(const std::string& filter);
}  // namespace cairn::bench

int main(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "--table") == 0) {
    const std::string which = argc >= 3 ? argv[2] : "";
    if (which == "chain-whip") return cairn::bench::chainWhipTable();
    if (which == "correction") return cairn::bench::correctionTable();
    if (which == "mass-ratio") return cairn::bench::massRatioTable();
    if (which == "extremes-variants") return cairn::bench::extremesVariantsTable(argc >= 4 ? argv[3] : "");
    if (which == "extremes-default") return cairn::bench::extremesDefaultTable(argc >= 4 ? argv[3] : "");
    if (which == "extremes") return cairn::bench::extremesTable(argc >= 4 ? argv[3] : "");
    std::cerr << "cairn_bench: --table takes chain-whip, correction, mass-ratio or extremes\n";
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
