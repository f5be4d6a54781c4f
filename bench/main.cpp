// cairn_bench: Google Benchmark timings (bench/pgs_bench.cpp), plus the
// measurement tables docs/constraints.md quotes, printed as Markdown:
//
//   cairn_bench [--benchmark_* flags]        timings
//   cairn_bench --table chain-whip           chain-20 whip: cairn and Bullet vs iterations
//   cairn_bench --table correction           position-correction modes compared
//   cairn_bench --table mass-ratio           hinge limit on a small box on a long arm
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
}  // namespace cairn::bench

int main(int argc, char** argv) {
  if (argc >= 2 && std::strcmp(argv[1], "--table") == 0) {
    const std::string which = argc >= 3 ? argv[2] : "";
    if (which == "chain-whip") return cairn::bench::chainWhipTable();
    if (which == "correction") return cairn::bench::correctionTable();
    if (which == "mass-ratio") return cairn::bench::massRatioTable();
    std::cerr << "cairn_bench: --table takes chain-whip, correction or mass-ratio\n";
    return 2;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
