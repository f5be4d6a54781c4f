#include "validation/bench_run.hpp"

#include "validation/bench_world.hpp"
#include "validation/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace cairn::validation {

namespace {

constexpr const char* kEngineNames[kBenchEngineCount] = {"cairn", "bullet_defaults", "bullet_matched"};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// Stacks stand from the start; dropped scenes come to rest, so only their
// last second says whether they rest. Trajectory scenes move by design.
RestFrom restFrom(const ValidationSpec& spec) {
  if (spec.kind != ValidationKind::Statistics) return RestFrom::None;
  return spec.scenario == "pile" || spec.scenario == "ragdoll" ? RestFrom::LastSecond : RestFrom::Start;
}

// The first sample at or after one second before the end (maxSince's rule).
int lastSecondStart(const SceneDesc& scene) {
  const double from = scene.steps * scene.dt - 1;
  int s = scene.steps;
  while (s > 0 && (s - 1) * scene.dt >= from - 1e-9) --s;
  return s;
}

// A run's per-body states are kept only where the figures read them (the
// start, the last second, and every sample when a trajectory is compared
// with the exact solve): a 5,050-box run of 600 steps would otherwise hold
// 240 MB of states.
void thinSample(EngineRun& run, int s) {
  std::vector<Vec3>().swap(run.positions[size_t(s)]);
  std::vector<Quat>().swap(run.orientations[size_t(s)]);
  std::vector<Vec3>().swap(run.velocities[size_t(s)]);
}

struct Measured {
  EngineRun run;
  double seconds = 0;
  std::array<double, kStageCount> stage_seconds{};
  double rows = 0, contacts = 0, contact_points = 0;  // sums over the steps
  int sleeping = 0;
  std::vector<std::string> notes;
};

// One run of `scene` in configuration `e`, stepped to the end or until it stops.
Measured runOnce(BenchEngine e, const SceneDesc& scene, const OracleOptions& oracle, const ValidationSpec& spec,
                 bool keep_every_sample) {
  Measured m;
  const int keep_from = keep_every_sample ? 0 : lastSecondStart(scene);
  const auto thin = [&](int s) {
    if (s > 0 && s < keep_from && s < m.run.samples()) thinSample(m.run, s);
  };
  if (e == BenchEngine::Cairn) {
    CairnRunner runner(scene, spec, m.run);
    std::array<int, kAloneReasonCount> alone{};  // steps on fewer threads than asked, by reason
    int steps = 0;
    for (int s = 1; s <= scene.steps && runner.step(s); ++s) {
      const StepReading r = readLastStep(runner.world());
      ++steps;
      if (r.threads < scene.solver.threads) ++alone[size_t(r.alone_because)];
      for (int k = 0; k < kStageCount; ++k) m.stage_seconds[size_t(k)] += r.stage_seconds[size_t(k)];
      m.rows += r.rows;
      m.contacts += r.contacts;
      m.contact_points += r.contact_points;
      m.sleeping = r.sleeping_bodies;
      thin(s - 1);
    }
    // A time on fewer threads than the table says must show.
    const auto note = [&](int n, const std::string& why) {
      if (n > 0)
        m.notes.push_back(std::to_string(n) + " of " + std::to_string(steps) + " steps on one thread, not " +
                          std::to_string(scene.solver.threads) + ": " + why);
    };
    note(alone[size_t(AloneReason::LostCores)],
         "the worker threads were losing their cores to other work (StepStats::threads)");
    note(alone[size_t(AloneReason::Probe)] + alone[size_t(AloneReason::NoGain)],
         std::to_string(alone[size_t(AloneReason::Probe)]) + " timed against steps on the threads, " +
             std::to_string(alone[size_t(AloneReason::NoGain)]) +
             " because steps alone were found faster (StepStats::alone_because)");
  } else {
    BulletRunner runner(scene, spec, m.run, oracle);
    for (int s = 1; s <= scene.steps && runner.step(s); ++s) thin(s - 1);
    m.sleeping = runner.sleepingBodies();
    m.notes = runner.skipped();
  }
  for (size_t s = 1; s < m.run.step_seconds.size(); ++s) m.seconds += m.run.step_seconds[s];
  return m;
}

// What one run says about accuracy, plus its counts: the part of a result
// that every repeat must reproduce exactly.
struct Figures {
  std::optional<double> rest, penetration, joint_error, exact;
  double rows = 0, contacts = 0, contact_points = 0;
  int sleeping = 0;
  bool operator==(const Figures&) const = default;
};

Figures figuresOf(const Measured& m, const SceneDesc& scene, const ValidationSpec& spec, RestFrom rest,
                  const EngineRun* reference) {
  Figures f;
  const EngineRun& run = m.run;
  const int steps = run.samples() - 1;
  if (steps < 1) return f;
  f.rows = m.rows / steps;
  f.contacts = m.contacts / steps;
  f.contact_points = m.contact_points / steps;
  f.sleeping = m.sleeping;
  const double duration = steps * scene.dt;
  if (rest == RestFrom::Start) f.rest = largestDisplacement(scene, run, 0, steps);
  if (rest == RestFrom::LastSecond) {
    SceneDesc ran = scene;
    ran.steps = steps;
    const int from = lastSecondStart(ran);
    // A run that stopped early may have had that sample thinned away.
    if (!run.positions[size_t(from)].empty()) f.rest = largestDisplacement(scene, run, from, steps);
  }
  if (!run.penetration.empty()) f.penetration = maxSince(run, run.penetration, std::max(0.0, duration - 1));
  if (!scene.joints.empty()) f.joint_error = maxSince(run, run.joint_error, 0);
  if (reference) f.exact = referenceDistance(run, *reference, spec, duration);
  return f;
}

}  // namespace

const char* benchEngineName(BenchEngine e) { return kEngineNames[size_t(e)]; }

BenchEngine benchEngine(int index) { return static_cast<BenchEngine>(index); }

const char* restFromName(RestFrom r) {
  switch (r) {
    case RestFrom::None: return "";
    case RestFrom::Start: return "start";
    case RestFrom::LastSecond: return "last_second";
  }
  return "";
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

double BenchEngineResult::medianMs() const { return median(ms_per_step); }

std::array<double, kStageCount> BenchEngineResult::medianStageMs() const {
  std::array<double, kStageCount> out{};
  for (int k = 0; k < kStageCount; ++k) {
    std::vector<double> v;
    for (const auto& r : stage_ms) v.push_back(r[size_t(k)]);
    out[size_t(k)] = median(v);
  }
  return out;
}

BenchSceneResult runBenchScene(const BenchScene& scene, int repeats,
                               const std::function<void(const std::string&)>& progress) {
  BenchSceneResult result;
  result.name = scene.name;
  result.family = scene.family;
  for (const BodyDef& b : scene.base.bodies) result.bodies += b.type == BodyType::Dynamic;
  result.joints = static_cast<int>(scene.base.joints.size());
  const ValidationSpec spec = validationSpec(scene.base);
  result.rest_from = restFrom(spec);

  // The exact solve of the base scene: one ruler for every configuration
  // (they all step with its dt), run once: it is deterministic and not timed.
  EngineRun reference;
  if (spec.direct_reference) {
    runDirectReference(scene.base, spec, reference);
    if (reference.samples() < 2) result.exact_note = "the exact solve stopped: " + reference.failure;
  }
  const EngineRun* ruler = reference.samples() > 1 ? &reference : nullptr;

  std::array<Figures, kBenchEngineCount> first;
  for (int r = 0; r < repeats; ++r) {
    for (int k = 0; k < kBenchEngineCount; ++k) {
      const BenchEngine e = benchEngine((r + k) % kBenchEngineCount);
      const SceneDesc& s = scene.scenes[size_t(e)];
      BenchEngineResult& out = result.engines[size_t(e)];
      Measured m = runOnce(e, s, scene.oracle[size_t(e)], spec, spec.direct_reference);
      if (e == BenchEngine::Cairn)  // its notes are per scene, Bullet's the same for all
        for (std::string& n : m.notes) n = scene.name + ", repeat " + std::to_string(r + 1) + ": " + n;
      const int steps = m.run.samples() - 1;
      out.steps = std::max(steps, 0);
      out.ms_per_step.push_back(steps > 0 ? 1e3 * m.seconds / steps : std::numeric_limits<double>::quiet_NaN());
      if (e == BenchEngine::Cairn) {
        std::array<double, kStageCount> stage{};
        for (int i = 0; i < kStageCount; ++i) stage[size_t(i)] = steps > 0 ? 1e3 * m.stage_seconds[size_t(i)] / steps : 0;
        out.stage_ms.push_back(stage);
      }
      const Figures f = figuresOf(m, s, spec, result.rest_from, ruler);
      if (r == 0) {
        first[size_t(e)] = f;
        out.rows = f.rows;
        out.contacts = f.contacts;
        out.contact_points = f.contact_points;
        out.sleeping_bodies = f.sleeping;
        out.rest_displacement = f.rest;
        out.penetration = f.penetration;
        out.joint_error = f.joint_error;
        out.exact_distance = f.exact;
        out.notes = m.notes;
        if (!m.run.failure.empty()) out.status = "stopped: " + m.run.failure;
      } else {
        if (!(f == first[size_t(e)]) && out.status == "ok")
          out.status = "repeat " + std::to_string(r + 1) + " gave other figures than the first (not deterministic)";
        for (const std::string& n : m.notes)  // cairn's note on threads may differ between repeats
          if (std::find(out.notes.begin(), out.notes.end(), n) == out.notes.end()) out.notes.push_back(n);
      }
      if (progress) progress(std::string(benchEngineName(e)) + " " + fmt("%.4g", out.ms_per_step.back()) + " ms/step");
    }
  }
  return result;
}

}  // namespace cairn::validation
