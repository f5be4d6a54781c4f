// The extremes suite (docs/extremes.md): scenes that push cairn to the edge
// of what a velocity-level PGS engine holds, each run in cairn (default
// settings, and a short list of stronger settings of which the best is
// kept) and in Bullet 3.24 (validation/bullet_oracle.hpp), recording
//
//   finite   no NaN or Inf in any body state, and no NumericalEvent;
//   bounded  E(t) <= E(0) + margin over the whole run, E = kinetic +
//            gravitational potential (+ springs): with no motors in these
//            scenes, gravity's work is exactly -dPE, so this is "kinetic
//            energy never above the start plus the work done by gravity".
//            margin = 5% of the scene's energy scale S = KE(0) +
//            sum m |g| (vertical extent of the scene + 1 m); ERP's position
//            feedback legitimately adds a little energy, a blow-up adds
//            orders of magnitude more (the table prints the excess / S);
//            a case with a kinematic body doing work has no bound ("n/a");
//   drift    one figure per case, named with the case (largest anchor
//            separation, largest displacement of any body, ...), and its
//            limit, set by the geometry, not by the result:
//              stacks and columns  5 cm per metre of box (a tenth of
//                                  docs/scenarios.md's 0.5 m collapse of a
//                                  1 m box; ten 5 mm slops)
//              hanging chains      1 cm (2% of a 0.5 m link)
//              swinging chains     5 cm (5% of a 1 m link)
//              hinges              1 cm
//            (the other figures name theirs where the case is made).
//
// A case HOLDS at a setting when it is finite (and no NumericalEvent),
// bounded and its drift is under its limit. A case that does not hold must
// be REPORTED by the World: a diagnostic (World::diagnostics) or a
// numerical event, never a silent failure.
//
// The same cases feed the table generator (`cairn_bench --table extremes`)
// and tests/long/extremes_test.cpp.
#pragma once

#include "cairn/scene.hpp"

#include <functional>
#include <string>
#include <vector>

namespace cairn::validation {

enum class DriftMeasure {
  JointSeparation,   // largest anchor separation of any joint over the run (m)
  Displacement,      // largest distance of any dynamic body from its start (m)
  WallPenetration,   // how far the first body's leading point got past x = wall_x (m)
  AngularMomentum,   // largest |L(t) - L(0)| / |L(0)| (zero gravity, no contacts)
  MaxSpeed           // largest speed of any dynamic body (m/s)
};
const char* driftMeasureName(DriftMeasure m);

struct SettingVariant {
  std::string label;
  std::function<void(SolverSettings&)> apply;
};

struct ExtremeCase {
  std::string name;
  std::string what;     // one line for the table
  SceneDesc scene;      // with cairn's default solver settings (sleeping off)
  DriftMeasure measure = DriftMeasure::Displacement;
  Real drift_scale = 1;      // drift is reported divided by this (e.g. the box size); 1 = metres
  Real drift_limit = 0;      // the case holds while drift < this (in the drift's units; see above)
  Real wall_x = 0;           // WallPenetration: the wall's near face
  Real leading_radius = 0;   // WallPenetration: the moving sphere's radius
  bool energy_bound = true;  // false: a kinematic body does work (no bound)
  std::vector<SettingVariant> extra_variants;  // tried besides the standard ones for "best"
};

struct ExtremeResult {
  bool finite = true;
  int numerical_events = 0;
  int diagnostics = 0;  // (sub)steps the World reported as inaccurate (World::diagnostics)
  std::vector<std::string> diagnostic_kinds;  // the kinds reported, in the order the World first reported them
  std::string first_event;     // "body 'x': stage (detail)"
  double energy_excess = 0;    // max over the run of (E(t) - E(0)) / S
  bool bounded = true;         // energy_excess <= kEnergyMargin (or no bound)
  double drift = 0;
  int steps_run = 0;
  std::vector<std::string> skipped;  // Bullet: features it could not map
};

inline constexpr double kEnergyMargin = 0.05;

// Every case of the suite, in table order.
std::vector<ExtremeCase> extremeCases();
// One case by name (throws InputError for an unknown name).
ExtremeCase extremeCase(const std::string& name);

// The standard stronger settings tried for "best" (more iterations,
// substeps, the direct solver), in order of cost.
std::vector<SettingVariant> standardVariants();

ExtremeResult runCairn(const ExtremeCase& c, const SolverSettings& settings);
ExtremeResult runBullet(const ExtremeCase& c);

// Finite, no NumericalEvent, bounded and drift < c.drift_limit.
bool holds(const ExtremeCase& c, const ExtremeResult& r);
// The World said something went wrong: a diagnostic or a numerical event.
bool reported(const ExtremeResult& r);

// best = the holding variant with the smallest drift (the first, cheaper
// one on a tie); when none holds, the finite and bounded one with the
// smallest drift; when none is, the default.
struct BestResult {
  std::string label;
  ExtremeResult result;
};
BestResult runBest(const ExtremeCase& c);

}  // namespace cairn::validation
