// `--method auto|pgs|direct|lcp`, `--substeps N` and `--iterations N` for
// `cairn run` and `cairn validate`: the scene file's solver.method,
// solver.substeps and solver.iterations, set from the command line through
// the same table as `cairn sweep --vary` (validation/solver_keys.hpp).
#pragma once

#include "cairn/scene.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace cairn::cli {

struct SolverOverrides {
  std::optional<std::string> method, substeps, iterations;
};

// Adds the three options to `cmd`; they fill `o`.
void addSolverOverrideOptions(CLI::App& cmd, SolverOverrides& o);

// Sets the given ones on `scene`. Throws InputError naming the option and
// the value (e.g. "--method: 'fast' is not a method").
void applySolverOverrides(const SolverOverrides& o, SceneDesc& scene);

// " --method M --substeps N --iterations N" for the ones given, to quote a
// command line.
std::string solverOverridesText(const SolverOverrides& o);

}  // namespace cairn::cli
