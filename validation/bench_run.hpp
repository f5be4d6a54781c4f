// One scene of `cairn bench` (docs/benchmarks.md, "cairn bench"): cairn
// and Bullet 3.24 in two configurations run the same scene in one process,
// taking turns run by run, each run timed step by step and measured with
// the validation code's own rulers (compare.hpp).
//
// The three engine configurations:
//   cairn            the scene's settings (plus the command's overrides
//                    and thread count)
//   bullet_defaults  Bullet as a plain program runs it: OracleOptions
//                    {match_cairn = false, bullet_deactivation = true}:
//                    btContactSolverInfo's defaults but for the scene's
//                    iteration count and step, Bullet's own deactivation,
//                    margins, friction directions and material rules (an
//                    explicit sleeping override from the command makes it
//                    follow the scene's sleeping instead)
//   bullet_matched   cairn's model mapped onto Bullet (match_cairn = true,
//                    the scene's sleeping), as `cairn validate` runs it
//
// Each repeat builds the three runs and hands them the machine in turns of
// a tenth of the run's steps (kTurnsPerRun): the first configuration's
// steps 1 to 60 of 600, the second's, the third's, then every
// configuration's steps 61 to 120, and so on. A shared virtual machine's
// speed changes in spells (on this project's, chain-100's step took 0.056
// or 0.077 ms from one 0.4 s run to the next); a run made in one piece,
// 36 ms for cairn's chain-100, could fall wholly inside a slow spell that
// the other configurations missed, and its ratio said more about the
// machine than the engines. In turns, the configurations share the
// spells (docs/benchmarks.md measures the spread of the per-repeat
// ratios both ways). Each turn starts on caches the other configurations
// used, a cost each configuration pays alike. Repeat r starts each round
// of turns with configuration r mod 3, so none always runs first or last.
// A run's time is the sum of its steps' wall times (World::step; Bullet's
// step) over the steps it made; the table reports the median over
// repeats. The runs
// are independent worlds and deterministic, so the turns change no figure
// (tested), the accuracy figures are those of the first repeat, and
// later repeats are checked to give the same figures.
//
// Accuracy figures of a run, each engine measured by the same code through
// a cairn World holding its states (compare.hpp):
//   rest displacement  a body that should rest: for statistics scenes, the
//                      largest distance a dynamic body moved from its start
//                      pose (stacks: compareRuns's drift) or, for scenes
//                      that are dropped and then settle (piles, the
//                      ragdoll), over the last second
//   penetration        deepest geometric overlap over the last second
//   joint error        largest anchor separation over the run
//   exact distance     scenes with "reference": "direct" (chains): largest
//                      distance from cairn's exact bilateral solve of the
//                      same scene (method direct, compare.hpp) over the
//                      spec's horizon
#pragma once

#include "cairn/scene.hpp"
#include "cairn/stats.hpp"
#include "validation/bullet_oracle.hpp"

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cairn::validation {

enum class BenchEngine { Cairn, BulletDefaults, BulletMatched };
inline constexpr int kBenchEngineCount = 3;
const char* benchEngineName(BenchEngine e);  // "cairn", "bullet_defaults", "bullet_matched"
BenchEngine benchEngine(int index);

// Where a scene's rest displacement is measured from.
enum class RestFrom { None, Start, LastSecond };
const char* restFromName(RestFrom r);  // "", "start", "last_second"

// A scene as each configuration runs it.
struct BenchScene {
  std::string name;    // scenario key or file stem
  std::string family;  // scenario type ("pyramid", "pile", "chain", ...), else the name
  SceneDesc base;      // the scene with the overrides for every engine: the exact reference solves this one
  std::array<SceneDesc, kBenchEngineCount> scenes;        // by BenchEngine; all with base's dt and steps
  std::array<OracleOptions, kBenchEngineCount> oracle;    // how the Bullet configurations build Bullet
  std::array<std::string, kBenchEngineCount> overrides;   // "iterations=4 steps=60": what differs from the file
};

struct BenchEngineResult {
  std::vector<double> ms_per_step;  // one per repeat: the run's step time / its steps (ms)
  std::vector<std::array<double, kStageCount>> stage_ms;  // cairn: per repeat, per stage, per step (ms)
  int steps = 0;                     // steps made (fewer than asked when a run stopped)
  double rows = 0, contacts = 0, contact_points = 0;  // cairn: mean over the steps (StepStats)
  int sleeping_bodies = 0;           // dynamic bodies asleep after the last step
  std::optional<double> rest_displacement, penetration, joint_error, exact_distance;
  std::string status = "ok";         // or why the run stopped, or that repeats disagreed
  std::vector<std::string> notes;    // what the Bullet configuration could not map (BulletOracle::skipped); for cairn, steps it ran on fewer threads than asked

  double medianMs() const;
  std::array<double, kStageCount> medianStageMs() const;
};

struct BenchSceneResult {
  std::string name, family;
  int bodies = 0;  // dynamic
  int joints = 0;
  RestFrom rest_from = RestFrom::None;
  std::string exact_note;  // why there is no exact distance where the scene asks for one
  std::array<BenchEngineResult, kBenchEngineCount> engines;
  const BenchEngineResult& operator[](BenchEngine e) const { return engines[size_t(e)]; }
};

// The median (the mean of the middle two for an even count); NaN when empty.
double median(std::vector<double> values);

// Turns of a run (see the top of this file).
inline constexpr int kTurnsPerRun = 10;

// Runs `scene` `repeats` times in each configuration (repeats >= 1).
// `progress` is told of each run as it finishes ("cairn 2.51 ms/step").
// `turn_steps` > 0 sets the steps of a turn instead (the whole run: no
// turns), for the test that the turns change no figure.
BenchSceneResult runBenchScene(const BenchScene& scene, int repeats,
                               const std::function<void(const std::string&)>& progress = {}, int turn_steps = 0);

}  // namespace cairn::validation
