// The extremes table of docs/extremes.md: every case of
// validation/extremes.hpp in cairn with default settings, in cairn with the
// best of a short list of stronger settings (more iterations, substeps, the
// direct solver, and per-case scaled tolerances), and in Bullet 3.24.
//
//   cairn_bench --table extremes [NAME-SUBSTRING]
//   cairn_bench --table extremes-variants NAME-SUBSTRING   every setting tried, per case
//   cairn_bench --table extremes-default [NAME-SUBSTRING]  default settings only (no Bullet):
//                                                          holds? reported? by which watchers
//
// Each cell: finite? / bounded? (energy excess over the start, in % of the
// scene's energy scale) / the case's drift figure. "holds (default)": finite,
// bounded and the drift under the case's limit (validation/extremes.hpp);
// "reported": for a case that does not hold, whether the World said so (a
// diagnostic or a numerical event) and with which kinds. Deterministic.
#include "validation/extremes.hpp"

#include <cstdio>
#include <string>
#include <vector>

namespace cairn::bench {

namespace {

std::string cell(const validation::ExtremeResult& r, bool energy_bound) {
  char buf[160];
  std::string finite = r.finite ? (r.numerical_events ? "caught " + std::to_string(r.numerical_events) : "yes") : "NaN";
  std::string bounded = !energy_bound ? "n/a" : (r.bounded ? "yes" : "no");
  if (energy_bound && r.finite) {
    std::snprintf(buf, sizeof buf, " (%+.2g%%)", 100 * r.energy_excess);
    bounded += buf;
  }
  std::snprintf(buf, sizeof buf, "%.3g", r.drift);
  std::string drift = r.finite ? std::string(buf) : "-";
  if (r.diagnostics > 0) drift += " (diagnosed in " + std::to_string(r.diagnostics) + " steps)";
  return finite + " / " + bounded + " / " + drift;
}

std::string holdsCell(const validation::ExtremeCase& c, const validation::ExtremeResult& r) {
  char buf[64];
  std::snprintf(buf, sizeof buf, " (limit %g)", c.drift_limit);
  return (validation::holds(c, r) ? "yes" : "no") + std::string(buf);
}

// "-" for a case that holds; else "yes (kinds)" or "NO".
std::string reportedCell(const validation::ExtremeCase& c, const validation::ExtremeResult& r) {
  if (validation::holds(c, r)) return "-";
  if (!validation::reported(r)) return "NO";
  std::string kinds;
  if (r.numerical_events > 0) kinds = "numerical event";
  for (const std::string& k : r.diagnostic_kinds) kinds += (kinds.empty() ? "" : ", ") + k;
  return "yes (" + kinds + ")";
}

}  // namespace

int extremesTable(const std::string& filter) {
  std::printf("finite? / bounded? (largest E(t) - E(0), %% of the energy scale; bound %.0f%%) / drift\n\n",
              100 * validation::kEnergyMargin);
  std::printf(
      "| case | drift figure | cairn default | holds (default) | reported | cairn best (setting) | Bullet 3.24 |\n"
      "|---|---|---|---|---|---|---|\n");
  for (const validation::ExtremeCase& c : validation::extremeCases()) {
    if (!filter.empty() && c.name.find(filter) == std::string::npos) continue;
    const validation::ExtremeResult def = validation::runCairn(c, c.scene.solver);
    const validation::BestResult best = validation::runBest(c);
    const validation::ExtremeResult bt = validation::runBullet(c);
    std::string measure = validation::driftMeasureName(c.measure);
    if (c.drift_scale != 1) measure += " (box sizes)";
    std::printf("| %s | %s | %s | %s | %s | %s (%s) | %s |\n", c.name.c_str(), measure.c_str(),
                cell(def, c.energy_bound).c_str(), holdsCell(c, def).c_str(), reportedCell(c, def).c_str(),
                cell(best.result, c.energy_bound).c_str(), best.label.c_str(), cell(bt, c.energy_bound).c_str());
    if (!def.first_event.empty()) std::fprintf(stderr, "%s default: first event %s\n", c.name.c_str(), def.first_event.c_str());
    std::fflush(stdout);
  }
  return 0;
}

int extremesDefaultTable(const std::string& filter) {
  std::printf("| case | cairn default | holds | reported |\n|---|---|---|---|\n");
  for (const validation::ExtremeCase& c : validation::extremeCases()) {
    if (!filter.empty() && c.name.find(filter) == std::string::npos) continue;
    const validation::ExtremeResult r = validation::runCairn(c, c.scene.solver);
    std::printf("| %s | %s | %s | %s |\n", c.name.c_str(), cell(r, c.energy_bound).c_str(), holdsCell(c, r).c_str(),
                reportedCell(c, r).c_str());
    std::fflush(stdout);
  }
  return 0;
}

int extremesVariantsTable(const std::string& filter) {
  std::printf("| case | setting | cairn |\n|---|---|---|\n");
  for (const validation::ExtremeCase& c : validation::extremeCases()) {
    if (c.name.find(filter) == std::string::npos) continue;
    std::vector<validation::SettingVariant> variants = validation::standardVariants();
    variants.insert(variants.begin(), {"default", [](SolverSettings&) {}});
    variants.insert(variants.end(), c.extra_variants.begin(), c.extra_variants.end());
    for (const validation::SettingVariant& v : variants) {
      SolverSettings s = c.scene.solver;
      v.apply(s);
      const validation::ExtremeResult r = validation::runCairn(c, s);
      std::printf("| %s | %s | %s |\n", c.name.c_str(), v.label.c_str(), cell(r, c.energy_bound).c_str());
      if (!r.first_event.empty()) std::printf("|  | first event | %s |\n", r.first_event.c_str());
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace cairn::bench
