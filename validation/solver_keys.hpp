// Solver settings named on the command line by their scene-file names
// (docs/scene-format.md, "solver"), plus "dt": the one table behind
// `cairn run/validate --method/--substeps/--iterations` (cli/solver_overrides)
// and `cairn sweep --vary KEY=V1,V2,...`.
//
// A value is text as the user wrote it. setSolverKey parses it, sets it on
// the scene and validates the result with the World's own rules
// (validateSettings), so a bad value is refused before anything runs, with
// an InputError naming the command-line option, the key and the value.
#pragma once

#include "cairn/scene.hpp"

#include <string>
#include <vector>

namespace cairn::validation {

// The keys setSolverKey accepts, in the order the sweep's table lists them:
// method, substeps, iterations, erp, dt, then the other solver settings.
const std::vector<std::string>& solverKeyNames();
bool isSolverKey(const std::string& key);
std::string solverKeyList();  // "method, substeps, ..." for messages

// Sets `key` to `value` on `scene` (dt on scene.dt, the rest on
// scene.solver). `option` names where the value came from in messages
// ("--vary iterations", "--method"): "--method: 'fast' is not a method
// (pgs, direct or lcp)". Throws InputError.
void setSolverKey(SceneDesc& scene, const std::string& key, const std::string& value, const std::string& option);

// The scene's current value of `key`, as the text setSolverKey reads back
// to the same value (numbers round-trip exactly).
std::string solverKeyValue(const SceneDesc& scene, const std::string& key);

// A finite decimal number or a fraction of two ("1/60"); throws InputError
// naming `option` and the text otherwise.
double parseNumberText(const std::string& option, const std::string& text);

// Shortest text that reads back to the same double.
std::string exactNumberText(double v);

}  // namespace cairn::validation
