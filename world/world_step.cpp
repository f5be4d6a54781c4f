// The step pipeline: the velocity-based step of section 12.6.2 of Dunn
// and Parberry's "3D Math Primer for Graphics and Game Development" (2nd
// ed., Listing 12.6), arranged as Box2D v3's solver.c arranges its stages.
// Top to bottom:
//
//   1. forces       springs, constant forces, timed impulses
//   2. collide      broadphase -> narrowphase -> contact cache -> callback
//   3. islands      wake what was touched; group awake bodies; order them
//   for each of the n substeps (h / n each):
//     4. velocities   v* = v + h M^-1 f (gravity, gyroscopic term, damping)
//     5. prepare      joint rows and contact constraints, island by island
//                     (direct and exact islands: with the joints' geometric
//                     stiffness in their inertia, restored after the solve)
//     6. solve        v = v* + M^-1 J^T lambda (PGS over the coloured
//                     constraint graph, or a direct or exact solve per
//                     island); then the position-correction passes
//     7. positions    x += h v, q <- exp(h w) q; then the joint position
//                     pass of direct and exact islands (Newton on C(x) = 0)
//     8. impulses     kept for warm starting; joint feedback and breaking
//   9. restitution  once, from the approach speeds at detection
//  10. events, sleep, clear accumulators
//
// Collision runs first, on the positions the step starts from, so that
// restitution sees the approach speed before gravity is added (stage 4).
// A guard after each stage stops the step for an island in which anything
// went non-finite (its bodies go back to the step's start, at rest) and lets
// the other islands step on (docs/extremes.md, "Safety nets").
#include "cairn/error.hpp"
#include "world/geometric_stiffness.hpp"
#include "world/position_pass_stage.hpp"
#include "world/step_stages.hpp"

#include <chrono>
#include <cmath>
#include <string>

namespace cairn::detail {

namespace {

// Wall time of each stage, added into StepStats::stage_seconds: one clock
// read per stage boundary.
class StageClock {
 public:
  explicit StageClock(StepStats& stats) : stats_(stats), last_(std::chrono::steady_clock::now()) {}
  void lap(Stage s) {
    const auto now = std::chrono::steady_clock::now();
    stats_.stage_seconds[static_cast<int>(s)] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  StepStats& stats_;
  std::chrono::steady_clock::time_point last_;
};

// The accumulators are spent: zero those that can hold anything, the
// bodies that moved (constant forces wake theirs), the springs' ends and
// what the API pushed, without reading every body.
void clearForces(WorldImpl& w, const StepContext& ctx) {
  const auto clear = [&](size_t i) {
    w.bodies_[i].force.setZero();
    w.bodies_[i].torque.setZero();
  };
  for (size_t i = 0; i < w.bodies_.size(); ++i)
    if (ctx.moves(i)) clear(i);
  for (const Spring& s : w.springs_)
    for (const BodyId id : {s.def.body_a, s.def.body_b})
      if (s.alive && !id.isWorld()) clear(static_cast<size_t>(id.index));
  for (const std::int32_t i : w.forced_bodies_)
    if (static_cast<size_t>(i) < w.bodies_.size()) clear(static_cast<size_t>(i));
  w.forced_bodies_.clear();
}

// The worker pool follows SolverSettings::threads, less the steps it sits
// out after its threads were found sharing their cores or not paying
// (world/pool_watch.hpp).
void fitPool(WorldImpl& w) {
  const int threads = w.settings_.threads;
  if (threads <= 1) {
    w.pool_.reset();
    w.parked_pool_.reset();
    w.pool_watch_.reset();
    return;
  }
  if (w.parked_pool_) {
    if (!w.pool_watch_.startStep()) return;
    w.pool_ = std::move(w.parked_pool_);
  }
  if (!w.pool_ || w.pool_->threads() != threads) {
    w.pool_ = std::make_unique<WorkerPool>(threads);
    w.pool_watch_.reset();
  }
}

// After the step, given its wall time so far: sets the pool aside when its
// threads lost their cores or when steps alone ran faster
// (world/pool_watch.hpp), and says why this step ran alone.
void watchPool(WorldImpl& w, double seconds) {
  if (!w.pool_) {
    if (!w.parked_pool_) return;
    w.stats_.alone_because = w.pool_watch_.aside();
    w.pool_watch_.endSoloStep(seconds, w.stats_.rows);
    return;
  }
  const std::int64_t preempted = w.pool_->takePreemptedWaits();
  // A step not handed a loop is not timed; with the lost cores' rule alone, none is.
  const bool handed = w.pool_rules_ == PoolRules::All && w.pool_->loops() > 0;
  if (w.pool_rules_ != PoolRules::None && w.pool_watch_.endPoolStep(preempted, handed, seconds, w.stats_.rows))
    w.parked_pool_ = std::move(w.pool_);
}

// Keeps the pool's workers waiting warm through the step (solver/worker_pool.hpp)
// when the last step handed it a loop, and lets them sleep after it,
// however the step ends.
class WarmPool {
 public:
  explicit WarmPool(WorldImpl& w) : w_(w) {
    if (w_.pool_ && w_.warm_pool_) w_.pool_->keepWarm(true);
  }
  ~WarmPool() {
    // Both pools' counts start again (a pool set aside this step must not
    // bring this step's loops back with it), the active one's decides.
    w_.warm_pool_ = false;
    for (WorkerPool* p : {w_.pool_.get(), w_.parked_pool_.get()}) {
      if (!p) continue;
      p->keepWarm(false);
      const bool handed = p->takeLoops() > 0;
      if (p == w_.pool_.get()) w_.warm_pool_ = handed;
    }
  }
  WarmPool(const WarmPool&) = delete;
  WarmPool& operator=(const WarmPool&) = delete;

 private:
  WorldImpl& w_;
};

}  // namespace

void WorldImpl::step(Real h) {
  if (!std::isfinite(h) || h <= 0)
    throw InputError("world", "dt", "time step must be positive and finite (got " + std::to_string(h) + ")");
  const auto t0 = std::chrono::steady_clock::now();
  stats_ = StepStats{};
  StageClock clock(stats_);
  StepContext& ctx = ctx_;
  const int n = settings_.substeps;
  ctx.h = h;
  ctx.hs = h / n;
  fitPool(*this);
  const WarmPool warm(*this);
  saveStepStart(*this, ctx);
  break_events_.clear();
  contact_events_.clear();
  clock.lap(Stage::Guards);

  applyForces(*this, ctx);  // 1
  clock.lap(Stage::Forces);
  collide(*this, ctx);  // 2
  clock.lap(Stage::Collide);
  buildIslands(*this, ctx);  // 3
  orderSolverBodies(*this, ctx);
  ctx.frozen_island.assign(static_cast<size_t>(ctx.island_count), 0);
  ctx.any_frozen = false;
  clock.lap(Stage::Islands);
  for (int sub = 0; sub < n; ++sub) {
    ctx.substep = sub;
    integrateVelocities(*this, ctx);  // 4
    clock.lap(Stage::Integrate);
    guardBodies(*this, ctx, "velocity integration");
    clock.lap(Stage::Guards);
    stiffenRotations(*this, ctx);    // 5a
    recordJointErrors(*this, ctx);
    prepareConstraints(*this, ctx);  // 5
    clock.lap(Stage::BuildRows);
    solveConstraints(*this, ctx);  // 6
    restoreRotations(*this, ctx);    // 6a
    clock.lap(Stage::Solve);
    guardSolve(*this, ctx);
    clock.lap(Stage::Guards);
    integratePositions(*this, ctx);  // 7
    clock.lap(Stage::Integrate);
    correctJointPositions(*this, ctx);  // 7b
    clock.lap(Stage::Integrate);
    guardBodies(*this, ctx, "position integration");
    clock.lap(Stage::Guards);
    if (sub + 1 < n) {
      storeImpulses(*this, ctx);  // 8
      clock.lap(Stage::Store);
    }
  }
  applyRestitution(*this, ctx);  // 9
  clock.lap(Stage::Solve);
  guardBodies(*this, ctx, "restitution");
  clock.lap(Stage::Guards);
  storeImpulses(*this, ctx);  // 8, last substep
  clock.lap(Stage::Store);
  emitContactEvents(*this, ctx);  // 10
  clock.lap(Stage::Events);
  updateSleep(*this, ctx);
  clock.lap(Stage::Sleep);
  watchStep(*this, ctx);  // diagnostics: what went wrong without a NaN; counts the contacts
  clock.lap(Stage::Guards);
  moveAwakeProxies(h);        // fat boxes hold the shapes where they ended, for queries between steps
  clock.lap(Stage::Collide);  // the broadphase's work, wherever in the step it happens
  clearForces(*this, ctx);
  saveStepEnd(*this, ctx);
  stats_.islands = ctx.island_count;
  stats_.threads = pool_ ? pool_->threads() : 1;
  watchPool(*this, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  clock.lap(Stage::Guards);
  ++step_count_;
  time_ += h;
  stats_.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace cairn::detail
