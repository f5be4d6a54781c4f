#include "cli/solver_overrides.hpp"

#include "validation/solver_keys.hpp"

namespace cairn::cli {

void addSolverOverrideOptions(CLI::App& cmd, SolverOverrides& o) {
  cmd.add_option("--method", o.method, "Solver: auto (per island), pgs, direct (CHOLMOD + PGS) or lcp (exact); overrides solver.method");
  cmd.add_option("--substeps", o.substeps, "Substeps per step (overrides solver.substeps)");
  cmd.add_option("--iterations", o.iterations, "PGS iterations per (sub)step (overrides solver.iterations)");
}

void applySolverOverrides(const SolverOverrides& o, SceneDesc& scene) {
  if (o.method) validation::setSolverKey(scene, "method", *o.method, "--method");
  if (o.substeps) validation::setSolverKey(scene, "substeps", *o.substeps, "--substeps");
  if (o.iterations) validation::setSolverKey(scene, "iterations", *o.iterations, "--iterations");
}

std::string solverOverridesText(const SolverOverrides& o) {
  std::string s;
  if (o.method) s += " --method " + *o.method;
  if (o.substeps) s += " --substeps " + *o.substeps;
  if (o.iterations) s += " --iterations " + *o.iterations;
  return s;
}

}  // namespace cairn::cli
