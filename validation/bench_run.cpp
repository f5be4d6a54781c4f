#include "validation/bench_run.hpp"

#include "validation/bench_world.hpp"
#include "validation/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

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

// One run of `scene` in configuration `e`, stepped a turn at a time
// (runBenchScene hands the three configurations the machine in turns) to
// the end or until it stops. Its runner writes into its own Measured, so
// it stays where it was made.
class TurnRun {
 public:
  TurnRun(BenchEngine e, const SceneDesc& scene, const OracleOptions& oracle, const ValidationSpec& spec,
          bool keep_every_sample)
      : engine_(e), scene_(scene), keep_from_(keep_every_sample ? 0 : lastSecondStart(scene)) {
    if (e == BenchEngine::Cairn) cairn_ = std::make_unique<CairnRunner>(scene, spec, m_.run);
    else bullet_ = std::make_unique<BulletRunner>(scene, spec, m_.run, oracle);
  }
  TurnRun(const TurnRun&) = delete;
  TurnRun& operator=(const TurnRun&) = delete;

  // Steps up to step `last` (1-based) unless the run has ended.
  void stepThrough(int last) {
    for (; running_ && next_ <= std::min(last, scene_.steps); ++next_) {
      running_ = cairn_ ? cairn_->step(next_) : bullet_->step(next_);
      if (!running_) break;
      if (cairn_) readCairnStep();
      thin(next_ - 1);
    }
  }

  // The finished run: its time and, for cairn, a note on steps taken on
  // fewer threads than asked.
  Measured finish() {
    if (cairn_) {  // a time on fewer threads than the table says must show
      const auto note = [&](int alone, const std::string& why) {
        if (alone > 0)
          m_.notes.push_back(std::to_string(alone) + " of " + std::to_string(steps_) + " steps on one thread, not " +
                             std::to_string(scene_.solver.threads) + ": " + why);
      };
      note(alone_[size_t(AloneReason::LostCores)],
           "the worker threads were losing their cores to other work (StepStats::threads)");
      note(alone_[size_t(AloneReason::Probe)] + alone_[size_t(AloneReason::NoGain)],
           std::to_string(alone_[size_t(AloneReason::Probe)]) + " timed against steps on the threads, " +
               std::to_string(alone_[size_t(AloneReason::NoGain)]) +
               " because steps alone were found faster (StepStats::alone_because)");
    } else {
      m_.sleeping = bullet_->sleepingBodies();
      m_.notes = bullet_->skipped();
    }
    for (size_t s = 1; s < m_.run.step_seconds.size(); ++s) m_.seconds += m_.run.step_seconds[s];
    cairn_.reset();
    bullet_.reset();
    return std::move(m_);
  }

  BenchEngine engine() const { return engine_; }

 private:
  void readCairnStep() {
    const StepReading r = readLastStep(cairn_->world());
    ++steps_;
    if (r.threads < scene_.solver.threads) ++alone_[size_t(r.alone_because)];
    for (int k = 0; k < kStageCount; ++k) m_.stage_seconds[size_t(k)] += r.stage_seconds[size_t(k)];
    m_.rows += r.rows;
    m_.contacts += r.contacts;
    m_.contact_points += r.contact_points;
    m_.sleeping = r.sleeping_bodies;
  }
  void thin(int s) {
    if (s > 0 && s < keep_from_ && s < m_.run.samples()) thinSample(m_.run, s);
  }

  BenchEngine engine_;
  const SceneDesc& scene_;
  int keep_from_;
  Measured m_;
  std::unique_ptr<CairnRunner> cairn_;
  std::unique_ptr<BulletRunner> bullet_;
  int next_ = 1;
  bool running_ = true;
  std::array<int, kAloneReasonCount> alone_{};  // cairn: steps on fewer threads than asked, by reason
  int steps_ = 0;                                // cairn: steps made
};

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
                               const std::function<void(const std::string&)>& progress, int turn_steps) {
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
  const int steps_asked = scene.base.steps;
  const int turn = turn_steps > 0 ? turn_steps : std::max(1, (steps_asked + kTurnsPerRun - 1) / kTurnsPerRun);
  for (int r = 0; r < repeats; ++r) {
    std::array<std::unique_ptr<TurnRun>, kBenchEngineCount> runs;  // in this repeat's order
    for (int k = 0; k < kBenchEngineCount; ++k) {
      const BenchEngine e = benchEngine((r + k) % kBenchEngineCount);
      runs[size_t(k)] = std::make_unique<TurnRun>(e, scene.scenes[size_t(e)], scene.oracle[size_t(e)], spec,
                                                  spec.direct_reference);
    }
    for (int from = 1; from <= steps_asked; from += turn)
      for (auto& run : runs) run->stepThrough(from + turn - 1);
    for (auto& run : runs) {
      const BenchEngine e = run->engine();
      const SceneDesc& s = scene.scenes[size_t(e)];
      BenchEngineResult& out = result.engines[size_t(e)];
      Measured m = run->finish();
      run.reset();
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
