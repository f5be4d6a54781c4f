// cairn against Bullet (and closed forms) on one scene: run both engines
// step by step with matched settings, record the same quantities from each,
// and turn them into figures checked against tolerances.
//
// Every per-step quantity is measured by the same code for both engines:
// Bullet's body states are copied into a shadow cairn World built from the
// same scene, and energy, momentum, joint error and penetration are read
// from it exactly as from cairn's own World. Penetration is geometric: the
// deepest overlap cairn's narrowphase finds between any two shapes that
// may collide (filtering and joined pairs as the World has them), so the
// two engines are judged by one ruler (Bullet's own manifold depths would
// include its collision margins).
//
// Two kinds of scene (the scene file's "validation.kind"):
//   trajectory  deterministic scenes (pendulums, chains, hinges, the door,
//               the ramp, a bouncing ball): the largest difference between
//               the engines in body position and orientation over the run.
//   statistics  chaotic scenes (pyramids, columns, piles, the ragdoll),
//               where the two engines' step-by-step states part ways by
//               design: resting height of the top body, the largest
//               displacement (drift), penetration over the last second and
//               collapse (any body moved more than 0.5 m), side by side.
// Both kinds add joint error, energy, momentum and wall time per step, and
// closed-form references where the scene has one (docs/validation.md, "How
// to read the report").
#pragma once

#include "cairn/scene.hpp"
#include "validation/bullet_oracle.hpp"
#include "validation/replay.hpp"
#include "world/world_access.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace cairn::validation {

enum class ValidationKind { Trajectory, Statistics };
const char* kindName(ValidationKind k);

// A quantity recorded every step for plots and analytic figures.
//   height        y of the body's center of mass (m)
//   x, z          x or z of the center of mass (m)
//   swing_angle   angle of the center of mass about +z around `pivot`,
//                 from straight down (rad)
//   angle         rotation of the body about `axis` since the start (rad)
//   slope         displacement along `axis` since the start (m)
struct TraceSpec {
  std::string body;
  std::string quantity = "height";
  Vec3 pivot = Vec3::Zero();
  Vec3 axis = Vec3::UnitY();
  std::string label() const { return body + " " + quantity; }
  std::string unit() const { return quantity == "swing_angle" || quantity == "angle" ? "rad" : "m"; }
};

// A closed-form reference (the scene file's "validation.analytic" list):
//   pendulum_period  {body, pivot, value, angle}: period of the swing angle
//                    (s); also the amplitude over the last period against
//                    the release angle `angle`
//   slide            {body, axis, value}: acceleration along `axis`
//                    (m/s^2) measured after `settle` seconds
//   stick            {body}: displacement over the run (0 m)
//   apex_ratio       {body, rest_height, value}: first rebound apex over
//                    the drop height, both above `rest_height` (e^2)
//   open_time        {body, axis, angle, value}: time until the body has
//                    turned 99% of `angle` about `axis` (s); also the
//                    final angle against `angle`
//   projectile       {body}: final center of mass against
//                    x0 + v0 t + g t^2 / 2 (no contact, no joint)
//   torque_free      {body}: rotational kinetic energy kept (J)
//   spring_period    {body, value}: period of the spring length (s)
struct AnalyticSpec {
  std::string type;
  std::string body;
  Vec3 pivot = Vec3::Zero();
  Vec3 axis = Vec3::UnitY();
  Real value = 0;
  Real rest_height = 0;
  Real angle = 0;
  Real settle = Real(0.5);
};

struct ValidationSpec {
  ValidationKind kind = ValidationKind::Statistics;
  std::string scenario;  // scenario type ("hinge-pendulum", "column", ...) or "" when inferred
  // Tolerances by figure key (docs/validation.md lists the keys); a
  // figure whose key has no tolerance is reported but not checked.
  std::map<std::string, Real> tolerances;
  std::vector<TraceSpec> traces;
  std::vector<AnalyticSpec> analytic;
  std::string top_body;  // statistics: whose resting height is read (default: highest start)
  Real collapse_distance = Real(0.5);
  // Trajectory scenes: the position and angle differences are checked over
  // [0, horizon] seconds only (0: the whole run); the whole run's figures
  // are still reported. A chaotic motion (chain-20's whip) parts two
  // engines, or one engine from itself at another iteration count, after
  // a while; past that time only statistics are comparable.
  Real horizon = 0;
  // Also run cairn with the exact bilateral solve (method "direct") as the
  // reference trajectory ("reference": "direct"), and report each engine's
  // distance from it over the horizon: which engine is closer to the
  // converged solution of the same equations, not only whether they agree.
  bool direct_reference = false;
};

// The scene's "validation" block with the defaults for its scenario type
// filled in; without a block the kind and references are inferred from
// the scene (a free body: projectile and torque-free; a body on one
// spring: spring period; joints and no static body: trajectory; else
// statistics). Throws InputError naming "validation" and the field.
ValidationSpec validationSpec(const SceneDesc& scene);

// Default tolerances of a scenario type and kind (docs/validation.md).
std::map<std::string, Real> defaultTolerances(const std::string& scenario, ValidationKind kind);

// One engine's record of a run; index 0 of every series is the start.
struct EngineRun {
  std::vector<double> time;
  std::vector<std::vector<Vec3>> positions;  // [sample][body], center of mass
  std::vector<std::vector<Quat>> orientations;
  std::vector<std::vector<Vec3>> velocities;
  std::vector<double> joint_error;        // largest linear joint error (m)
  std::vector<double> joint_error_angular; // largest angular joint error (rad)
  std::vector<double> energy;             // kinetic + potential (J)
  std::vector<double> rotational_energy;  // sum of 1/2 w.Lw (J)
  std::vector<Vec3> momentum;             // linear (kg m/s)
  std::vector<double> penetration;        // deepest overlap (m)
  std::vector<double> step_seconds;       // wall time of each step (sample 0: 0)
  std::vector<std::vector<double>> traces;  // [trace][sample]
  std::vector<double> spring_length;       // first spring (m), if any
  std::string failure;  // non-empty when the run stopped (e.g. non-finite state)
  int samples() const { return static_cast<int>(time.size()); }
};

// A figure of the report: both engines side by side, a closed-form value
// where there is one, and the check that decides pass or fail (cairn is
// judged; Bullet's figures are shown for reference).
enum class Check {
  None,            // reported only
  AtMost,          // cairn <= tolerance
  DiffBullet,      // |cairn - Bullet| <= tolerance
  DiffAnalytic,    // |cairn - analytic| <= tolerance
  RelAnalytic,     // |cairn - analytic| / |analytic| <= tolerance
  NotWorseFlag,    // a yes/no figure (1 = yes): cairn may say yes only if Bullet does
  RatioBullet,     // cairn <= tolerance x Bullet (no worse than the reference by that factor)
};

struct Figure {
  std::string key;   // tolerance key ("position", "period", ...)
  std::string name;  // for people ("largest position difference")
  std::string unit;
  std::optional<double> cairn, bullet, analytic;
  Check check = Check::None;
  double tolerance = 0;
  bool summary = false;  // shown in the one-line-per-scene summary
  // Filled by evaluate():
  bool pass = true;
  double excess = 0;  // how far past the tolerance (in the figure's unit, or a fraction for RelAnalytic)
  std::string note;
  void evaluate();
  std::string checkText() const;  // "|cairn - Bullet| <= 0.01 m"
};

struct SceneResult {
  std::string name;    // scenario key or file name as given
  std::string source;  // the file path, or "standard scenario"
  std::string description;
  SceneDesc scene;
  ValidationSpec spec;
  EngineRun cairn, bullet;
  EngineRun reference;  // cairn, method "direct", when spec.direct_reference
  std::vector<Figure> figures;
  std::vector<std::string> skipped;  // what Bullet lacks (BulletOracle::skipped)
  // cairn's run recorded for the viewer with Bullet's beside it, when asked
  // for (validateScene's record_replay).
  std::shared_ptr<Replay> replay;
  bool pass() const;
  std::vector<const Figure*> failures() const;
};

// Runs `scene` in cairn and in Bullet (OracleOptions{match_cairn = true})
// for scene.steps steps and fills cairn, bullet and skipped, and the
// reference when spec.direct_reference; with record_replay also
// result.replay (replay_bullet.hpp).
void runEngines(SceneResult& result, bool record_replay = false);

// The reference run of a scene with "reference": "direct": cairn on the
// same scene with method "direct" (the exact bilateral solve), recorded
// like the others, for scene.steps steps or until it stops.
void runDirectReference(const SceneDesc& scene, const ValidationSpec& spec, EngineRun& out);

// Records samples from a cairn World: the real one, or the shadow one that
// holds Bullet's states. One Recorder per engine (it keeps the first
// sample as the reference of the traces).
class Recorder {
 public:
  Recorder(const SceneDesc& scene, const ValidationSpec& spec);
  void record(const World& world, double time, double step_seconds, EngineRun& run);

 private:
  const ValidationSpec& spec_;
  std::vector<int> trace_body_;
  std::vector<std::uint64_t> joined_;  // body pairs a joint keeps apart (sorted keys)
  bool contacts_possible_ = false;
  std::vector<Vec3> start_position_;
  std::vector<Quat> start_orientation_;
  bool started_ = false;
};

// One engine's run, stepped by the caller (runEngines steps both in turn;
// `cairn sweep` runs them apart and looks at the World between steps).
// The constructor records sample 0; step(s) advances by scene.dt, records
// sample s and returns false once the run has stopped (the reason is in
// the EngineRun's failure). `scene` and `spec` must outlive the runner.
// With `replay`, every sample is also recorded there for the viewer.
class ReplayRecorder;
class CairnRunner {
 public:
  CairnRunner(const SceneDesc& scene, const ValidationSpec& spec, EngineRun& out, Replay* replay = nullptr);
  ~CairnRunner();
  bool step(int s);
  bool running() const { return running_; }
  const World& world() const { return world_; }

 private:
  Real dt_;
  World world_;
  Recorder recorder_;
  EngineRun& out_;
  std::unique_ptr<ReplayRecorder> replay_;
  bool running_ = true;
};

class BulletOracle;

// Bullet (OracleOptions{match_cairn = true} unless told otherwise),
// measured through a shadow cairn World that holds Bullet's states (see the
// top of this file).
class BulletRunner {
 public:
  BulletRunner(const SceneDesc& scene, const ValidationSpec& spec, EngineRun& out, const OracleOptions& options = {});
  ~BulletRunner();
  bool step(int s);
  bool running() const { return running_; }
  // What Bullet lacks or maps only approximately (BulletOracle::skipped).
  const std::vector<std::string>& skipped() const;
  int sleepingBodies() const;  // BulletOracle::sleepingBodies

 private:
  Real dt_;
  World shadow_;
  std::unique_ptr<BulletOracle> oracle_;
  Recorder recorder_;
  EngineRun& out_;
  bool running_ = true;
};

// Deepest overlap (m, >= 0) between shapes of `world` that may collide:
// cairn's narrowphase on the current poses, pairs filtered by collision
// group and mask and by joints (`joined`: sorted keys min(a,b) << 32 | max).
double geometricPenetration(const World& world, const std::vector<std::uint64_t>& joined);

// Figures from two runs: the comparison proper. Pure: no engine is run.
std::vector<Figure> compareRuns(const SceneDesc& scene, const ValidationSpec& spec, const EngineRun& cairn,
                                const EngineRun& bullet, const EngineRun* reference = nullptr);

// The largest difference between two runs over all samples and bodies.
struct TrajectoryDifference {
  double position = 0;  // m
  int position_body = -1, position_sample = -1;
  double angle = 0;     // rad
  int angle_body = -1, angle_sample = -1;
};
// Samples after `until` seconds (when > 0) are left out.
TrajectoryDifference trajectoryDifference(const EngineRun& a, const EngineRun& b, double until = 0);

// Largest distance any dynamic body moved between samples `from` and `to`
// (centers of mass). compareRuns's drift is from sample 0 to the last.
double largestDisplacement(const SceneDesc& scene, const EngineRun& run, int from, int to);

// Largest value of `v` over the samples of `run` at time >= t_from (0 when
// there are none).
double maxSince(const EngineRun& run, const std::vector<double>& v, double t_from);

// A run's largest position distance from the reference run (the exact
// bilateral solve) over the spec's horizon, or over the whole run when the
// horizon is 0 or not shorter than `duration` (s): compareRuns's
// reference_distance.
double referenceDistance(const EngineRun& run, const EngineRun& reference, const ValidationSpec& spec,
                         double duration);

// Mean period of a signal from its upward crossings of its mean level,
// linearly interpolated; 0 with fewer than two crossings.
double measurePeriod(const std::vector<double>& t, const std::vector<double>& x);

// Everything for one scene: run both engines and compare.
SceneResult validateScene(const SceneDesc& scene, const std::string& name, const std::string& source,
                          const std::string& description, bool record_replay = false);

}  // namespace cairn::validation
