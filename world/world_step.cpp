// The step pipeline (../shared/ARCHITECTURE.md, Listing 12.6 of the seed
// chapter), top to bottom:
//
//   1. forces       springs and user forces into the accumulators
//   2. collision    broadphase -> narrowphase -> contact cache -> callback
//   3. islands      wake what was touched; group awake bodies
//   for each of the n substeps (h / n each; Box2D v3's soft step):
//     4. velocities   v* = v + h M^-1 f (gravity, gyroscopic term, damping)
//     5. rows         joints, limits, motors, contacts -> Jacobian rows, island by island
//     6. solve        PGS per island: v = v* + M^-1 J^T lambda; then the
//                     position-correction pass (Baumgarte or split impulse)
//     7. positions    x += h v, q <- exp(h w) q
//     8. impulses     kept for warm starting; joint feedback and breaking
//   9. events, sleep, clear accumulators
//
// Collision runs first, on the positions the step starts from, so that
// restitution sees the approach speed before gravity is added (stage 4).
// A guard after each stage stops the step for an island in which anything
// went non-finite (its bodies go back to the step's start, at rest) and lets
// the other islands step on (docs/extremes.md, "Safety nets").
#include "cairn/error.hpp"
#include "dynamics/forces.hpp"
#include "dynamics/integrate.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"
#include "solver/pgs.hpp"
#include "world/world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace cairn {

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

}  // namespace

void World::step(Real h) {
  if (!std::isfinite(h) || h <= 0)
    throw InputError("world", "dt", "time step must be positive and finite (got " + std::to_string(h) + ")");
  const auto t0 = std::chrono::steady_clock::now();
  stats_ = StepStats{};
  StageClock clock(stats_);
  saveStepStart();
  break_events_.clear();
  contact_events_.clear();
  clock.lap(Stage::Guards);

  const int n = settings_.substeps;
  const Real hs = h / n;
  applyExternalForces();                                  // 1
  clock.lap(Stage::Forces);
  detectContacts(h);                                      // 2
  clock.lap(Stage::Collide);
  buildIslands();                                         // 3
  frozen_island_.assign(static_cast<size_t>(island_count_), 0);
  any_frozen_ = false;
  clock.lap(Stage::Islands);
  for (int sub = 0; sub < n; ++sub) {
    integrateVelocities(hs);                              // 4
    clock.lap(Stage::Integrate);
    guardBodies("velocity integration");
    clock.lap(Stage::Guards);
    buildRows(hs);                                        // 5
    clock.lap(Stage::BuildRows);
    guardRows("row building");
    clock.lap(Stage::Guards);
    solveRows();                                          // 6 (guards each island's rows after its solve)
    clock.lap(Stage::Solve);
    guardBodies("constraint solve");
    clock.lap(Stage::Guards);
    integratePositions(hs);                               // 7
    clock.lap(Stage::Integrate);
    guardBodies("position integration");
    clock.lap(Stage::Guards);
    storeImpulses(hs);                                    // 8
    clock.lap(Stage::Store);
  }
  emitContactEvents(old_contacts_);                       // 9
  clock.lap(Stage::Events);
  updateSleep(h);
  clock.lap(Stage::Sleep);
  clearAccumulators();
  saveStepEnd();

  for (const Contact& c : contacts_) {
    if (!c.enabled) continue;
    ++stats_.contacts;
    stats_.contact_points += c.count;
  }
  stats_.islands = island_count_;
  stats_.max_penetration = maxPenetration();
  clock.lap(Stage::Guards);
  ++step_count_;
  time_ += h;
  stats_.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Stage 5: rows island by island, so each island is solved on its own.
void World::buildRows(Real h) {
  rows_.clear();
  island_rows_.clear();
  const JointRowSettings jrs{settings_.restitution_threshold};
  ContactRowSettings crs;
  crs.h = h;
  crs.contact_erp = settings_.contact_erp;
  crs.cfm = settings_.cfm;
  crs.slop = settings_.slop;
  crs.restitution_threshold = settings_.restitution_threshold;
  crs.max_correction_velocity = settings_.max_correction_velocity;
  crs.correction = settings_.split_impulse ? Correction::PseudoVelocity : settings_.position_correction;
  crs.warm_start = settings_.warm_start;
  crs.warm_start_factor = settings_.warm_start_factor;

  // The island of a constraint is that of its dynamic, awake body (-1: none
  // awake, so it makes no rows).
  const auto islandOf = [&](BodyId a, BodyId b) {
    const std::int32_t ia = a.isWorld() ? -1 : body_island_[static_cast<size_t>(a.index)];
    return ia >= 0 ? ia : (b.isWorld() ? -1 : body_island_[static_cast<size_t>(b.index)]);
  };
  // Bucket joints and contacts by island (counting sort keeps the order).
  std::vector<std::int32_t> joint_start(static_cast<size_t>(island_count_) + 1, 0);
  std::vector<std::int32_t> contact_start(static_cast<size_t>(island_count_) + 1, 0);
  for (const Joint& j : joints_)
    if (!j.broken)
      if (const std::int32_t isl = islandOf(j.def.body_a, j.def.body_b); isl >= 0) ++joint_start[static_cast<size_t>(isl) + 1];
  for (const Contact& c : contacts_)
    if (c.enabled)
      if (const std::int32_t isl = islandOf(c.body_a, c.body_b); isl >= 0) ++contact_start[static_cast<size_t>(isl) + 1];
  for (size_t i = 1; i < joint_start.size(); ++i) {
    joint_start[i] += joint_start[i - 1];
    contact_start[i] += contact_start[i - 1];
  }
  std::vector<std::int32_t> joint_order(static_cast<size_t>(joint_start.back()));
  std::vector<std::int32_t> contact_order(static_cast<size_t>(contact_start.back()));
  {
    std::vector<std::int32_t> jf(joint_start.begin(), joint_start.end() - 1), cf(contact_start.begin(), contact_start.end() - 1);
    for (size_t i = 0; i < joints_.size(); ++i)
      if (!joints_[i].broken)
        if (const std::int32_t isl = islandOf(joints_[i].def.body_a, joints_[i].def.body_b); isl >= 0)
          joint_order[static_cast<size_t>(jf[static_cast<size_t>(isl)]++)] = static_cast<std::int32_t>(i);
    for (size_t i = 0; i < contacts_.size(); ++i)
      if (contacts_[i].enabled)
        if (const std::int32_t isl = islandOf(contacts_[i].body_a, contacts_[i].body_b); isl >= 0)
          contact_order[static_cast<size_t>(cf[static_cast<size_t>(isl)]++)] = static_cast<std::int32_t>(i);
  }

  for (std::int32_t isl = 0; isl < island_count_; ++isl) {
    const auto begin = static_cast<std::int32_t>(rows_.size());
    for (std::int32_t k = joint_start[static_cast<size_t>(isl)]; k < joint_start[static_cast<size_t>(isl) + 1]; ++k) {
      const auto i = static_cast<size_t>(joint_order[static_cast<size_t>(k)]);
      const Joint& j = joints_[i];
      RowContext ctx;
      ctx.h = h;
      ctx.erp = settings_.erp;
      ctx.cfm = settings_.cfm;
      ctx.joint_softness = &j.def.softness;
      ctx.owner = static_cast<std::int32_t>(i);
      ctx.rows = &rows_;
      ctx.warm = settings_.warm_start ? &j.warm : nullptr;
      ctx.warm_factor = settings_.warm_start_factor;
      ctx.max_correction_velocity = settings_.max_correction_velocity;
      // The direct and exact solvers solve the ERP target with the rest in
      // one exact solve: nothing is left for a correction pass to fix.
      ctx.correction = settings_.method == SolverMethod::PGS ? settings_.position_correction : Correction::InRhs;
      buildJointRows(j, view(j.def.body_a), view(j.def.body_b), ctx, jrs);
    }
    const std::int32_t c0 = contact_start[static_cast<size_t>(isl)], c1 = contact_start[static_cast<size_t>(isl) + 1];
    for (std::int32_t k = c0; k < c1; ++k) {
      const auto i = static_cast<size_t>(contact_order[static_cast<size_t>(k)]);
      Contact& c = contacts_[i];
      buildContactNormalRows(c, static_cast<std::int32_t>(i), view(c.body_a), view(c.body_b), crs, rows_);
    }
    for (std::int32_t k = c0; k < c1; ++k) {
      const auto i = static_cast<size_t>(contact_order[static_cast<size_t>(k)]);
      Contact& c = contacts_[i];
      buildContactFrictionRows(c, static_cast<std::int32_t>(i), view(c.body_a), view(c.body_b), crs, begin, rows_);
    }
    island_rows_.emplace_back(begin, static_cast<std::int32_t>(rows_.size()));
  }
  stats_.rows = static_cast<int>(rows_.size());
  for (int& k : stats_.rows_by_kind) k = 0;
  for (const ConstraintRow& r : rows_) ++stats_.rows_by_kind[static_cast<int>(r.kind)];
}

// Stage 6: v = v* + M^-1 J^T lambda, island by island.
void World::solveRows() {
  if (rows_.empty()) return;
  solver_bodies_.resize(bodies_.size() + 1);
  solver_bodies_[0] = SolverBody{};
  for (size_t i = 0; i < bodies_.size(); ++i)
    solver_bodies_[i + 1] = SolverBody{bodies_[i].linear_velocity, bodies_[i].angular_velocity};
  if (!rng_seeded_) {
    rng_state_ = settings_.seed;
    rng_seeded_ = true;
  }
  PgsSettings ps{settings_.iterations, settings_.tolerance, settings_.sor, settings_.randomize_order,
                 settings_.seed};
  ps.nncg = settings_.nncg;
  std::span<ConstraintRow> all(rows_);
  Real residual = 0;
  for (const auto& [begin, end] : island_rows_) {
    std::span<ConstraintRow> rows = all.subspan(static_cast<size_t>(begin), static_cast<size_t>(end - begin));
    switch (settings_.method) {
      case SolverMethod::PGS: {
        applyWarmStart(rows, solver_bodies_);
        const PgsStats st = solvePgs(rows, solver_bodies_, ps, pgs_scratch_, rng_state_);
        stats_.iterations = std::max(stats_.iterations, st.iterations);
        break;
      }
      case SolverMethod::Direct: {
        // CHOLMOD for the bilateral rows, PGS sweeps for the bounded ones,
        // alternated (solver/direct_solver.hpp); warm-started from lambda.
        DirectSolverOptions o;
        o.inner_pgs_iterations = settings_.iterations;
        o.warm_start = settings_.warm_start;
        const DirectSolveStats st = direct_solver_.solve(rows, solver_bodies_, o);
        stats_.iterations = std::max(stats_.iterations, st.outer_iterations);
        break;
      }
      case SolverMethod::LCP: {
        // Dantzig pivoting to the exact mixed-LCP solution (small scenes).
        const ExactLcpResult st = solveLcpExact(rows, solver_bodies_);
        stats_.iterations = std::max(stats_.iterations, st.pivots);
        break;
      }
    }
    residual = std::max(residual, lcpResidual(rows, solver_bodies_));
    guardIslandSolve(begin, end);  // a NaN born here stays in its island
  }
  stats_.residual = residual;
  // Position correction in its own passes (constraints/row.hpp, Correction):
  // Baumgarte's bias velocities join the state; split impulse's
  // pseudo-velocities move the bodies this step but add no momentum or
  // kinetic energy.
  solvePgsCorrection(rows_, solver_bodies_, Correction::VelocityBias, ps, pseudo_lambda_);
  pseudo_bodies_.assign(solver_bodies_.size(), SolverBody{});
  if (!solvePgsCorrection(rows_, pseudo_bodies_, Correction::PseudoVelocity, ps, pseudo_lambda_))
    pseudo_bodies_.clear();
  for (size_t i = 0; i < bodies_.size(); ++i) {
    if (!bodies_[i].isDynamic() || bodies_[i].asleep) continue;
    bodies_[i].linear_velocity = solver_bodies_[i + 1].v;
    bodies_[i].angular_velocity = solver_bodies_[i + 1].w;
  }
}

// Stage 8: keeps each row's impulse for warm starting, turns the impulses
// into the joints' force feedback (lambda / h through J), and breaks joints
// whose force or torque exceeded their threshold.
void World::storeImpulses(Real h) {
  for (Joint& j : joints_) {
    std::fill(j.warm.begin(), j.warm.end(), Real(0));
    j.feedback = JointFeedback{};
  }
  for (const ConstraintRow& r : rows_) {
    if (r.owner < 0 || r.kind >= RowKind::ContactNormal) continue;
    Joint& j = joints_[static_cast<size_t>(r.owner)];
    j.warm[static_cast<size_t>(r.owner_row)] = r.lambda;
    const Real f = r.lambda / h;
    j.feedback.force_a += r.j_lin_a * f;
    j.feedback.torque_a += r.j_ang_a * f;
    j.feedback.force_b += r.j_lin_b * f;
    j.feedback.torque_b += r.j_ang_b * f;
  }
  for (Contact& c : contacts_)
    if (c.enabled) storeContactImpulses(c, rows_);
  for (size_t i = 0; i < joints_.size(); ++i) {
    Joint& j = joints_[i];
    if (j.broken) continue;
    const Real force = j.feedback.force_b.norm();
    // Torque about the anchor on b: remove the moment of the force about b's center.
    const Vec3 anchor_b = j.def.body_b.isWorld() ? j.local_anchor_b : body(j.def.body_b).transform().apply(j.local_anchor_b);
    const Vec3 arm = anchor_b - (j.def.body_b.isWorld() ? Vec3::Zero() : body(j.def.body_b).position);
    const Real torque = (j.feedback.torque_b - arm.cross(j.feedback.force_b)).norm();
    if (force > j.def.break_force || torque > j.def.break_torque) {
      break_events_.push_back({step_count_, JointId{static_cast<std::int32_t>(i)}, j.def.name, force, torque});
      removeJoint(JointId{static_cast<std::int32_t>(i)});
    }
  }
}

void World::applyExternalForces() {
  for (const auto& s : springs_) {
    Body* a = s.def.body_a.isWorld() ? nullptr : &body(s.def.body_a);
    Body* b = s.def.body_b.isWorld() ? nullptr : &body(s.def.body_b);
    applySpring(a, s.local_a, b, s.local_b, s.rest_length, s.def.stiffness, s.def.damping);
  }
}

void World::integrateVelocities(Real h) {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    Body& b = bodies_[i];
    if (b.asleep) continue;
    bool gyro_ok = true;
    orientation_offset_[i] = integrateVelocity(b, gravity_, h, settings_.gyroscopic, &gyro_ok);
    if (!gyro_ok)
      diagnose(i, "gyroscopic solve",
               "implicit-midpoint gyroscopic step not solved to 1e-10 |L| (h |w| = " +
                   std::to_string(h * b.angular_velocity.norm()) + " rad): energy and |L| not conserved; substeps with h |w| < 1 restore it");
    // Safety net: cap the spin rate (off by default). stableNorm: |w|^2
    // must not overflow for the very spins the cap is there to catch.
    if (settings_.max_angular_velocity < kInf) {
      const Real w = b.angular_velocity.stableNorm();
      if (w > settings_.max_angular_velocity) b.angular_velocity *= settings_.max_angular_velocity / w;
    }
  }
}

void World::diagnose(size_t body, const char* kind, const std::string& detail) {
  for (Diagnostic& d : diagnostics_)
    if (d.body.index == static_cast<std::int32_t>(body) && d.kind == kind) {
      ++d.count;
      return;
    }
  diagnostics_.push_back({BodyId{static_cast<std::int32_t>(body)}, bodies_[body].name, kind, detail, step_count_, 1});
}

void World::integratePositions(Real h) {
  const bool pseudo = pseudo_bodies_.size() == bodies_.size() + 1;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    Body& b = bodies_[i];
    if (b.asleep) continue;
    if (pseudo && b.isDynamic()) {
      // Positions move at v + v_pseudo; the state velocity stays v.
      const SolverBody& p = pseudo_bodies_[i + 1];
      b.position += h * p.v;
      integratePosition(b, h, settings_.orientation, orientation_offset_[i] + p.w);
    } else {
      integratePosition(b, h, settings_.orientation, orientation_offset_[i]);
    }
  }
  pseudo_bodies_.clear();
}

void World::clearAccumulators() {
  for (auto& b : bodies_) {
    b.force.setZero();
    b.torque.setZero();
  }
}

// --- The NaN/Inf guard ---------------------------------------------------
//
// No NaN leaves a step silently. step_start_ holds each body's last good
// state: taken at the end of every step and again at the start of the next
// (to keep what the API set in between). After each stage the guard looks
// for non-finite body states (and, after building and after solving, for
// non-finite row data, so the stage reported is the one where the NaN was
// born). The island it finds one in is stopped for the rest of the step:
// every awake dynamic body of it goes back to its step-start pose, at rest,
// its rows are made inert (zero Jacobian, zero impulse, so nothing is
// stored for warm starting and nothing reaches the static bodies other
// islands share), and it is held there after every later stage. Islands
// are solved apart, so the others step exactly as if it were not there.
// One event per stopped island names the body, the stage and the island.
//
// Velocities are zeroed rather than restored: the restored island then has
// no more energy than at the step's start, and a blow-up driven by the
// velocity itself (a spin the integrator cannot take) is not replayed step
// after step; see docs/extremes.md.

namespace {

bool finiteState(const Body& b) {
  return b.position.allFinite() && b.orientation.coeffs().allFinite() && b.linear_velocity.allFinite() &&
         b.angular_velocity.allFinite();
}

const char* badField(const Body& b) {
  if (!b.position.allFinite()) return "position";
  if (!b.orientation.coeffs().allFinite()) return "orientation";
  if (!b.linear_velocity.allFinite()) return "linear velocity";
  return "angular velocity";
}

// The first non-finite number of a row ("" when all are finite). Bounds may
// be infinite, never NaN.
const char* badRowField(const ConstraintRow& r) {
  // Fast path: a NaN or infinity anywhere makes the sum non-finite (the
  // bounds may be infinite and are tested apart). Only a sum that is not
  // finite, rare, is looked at field by field.
  const Real sum = r.rhs + r.bias_rhs + r.lambda + r.inv_diag + r.cfm + r.mu + r.j_lin_a.sum() + r.j_ang_a.sum() +
                   r.j_lin_b.sum() + r.j_ang_b.sum() + r.m_lin_a.sum() + r.m_ang_a.sum() + r.m_lin_b.sum() +
                   r.m_ang_b.sum();
  if (std::isfinite(sum) && !std::isnan(r.lo) && !std::isnan(r.hi)) return "";
  if (!std::isfinite(r.rhs)) return "rhs";
  if (!std::isfinite(r.bias_rhs)) return "position-correction target";
  if (!std::isfinite(r.lambda)) return "impulse";
  if (!std::isfinite(r.inv_diag) || !std::isfinite(r.cfm)) return "effective mass";
  if (!(r.j_lin_a.allFinite() && r.j_ang_a.allFinite() && r.j_lin_b.allFinite() && r.j_ang_b.allFinite() &&
        r.m_lin_a.allFinite() && r.m_ang_a.allFinite() && r.m_lin_b.allFinite() && r.m_ang_b.allFinite()))
    return "Jacobian";
  if (std::isnan(r.lo) || std::isnan(r.hi) || std::isnan(r.mu)) return "bounds";
  return "";
}

}  // namespace

void World::saveStepStart() {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    Body& b = bodies_[i];
    if (finiteState(b)) {
      step_start_[i] = {b.position, b.orientation, b.linear_velocity, b.angular_velocity};
      continue;
    }
    // Set through the API since the last step (Body& access, a NaN impulse):
    // back to the last good state. Its island has not moved yet, so this
    // body alone is restored and the step goes on.
    const char* what = badField(b);
    restoreBody(i);
    numerical_events_.push_back({step_count_, BodyId{static_cast<std::int32_t>(i)}, b.name, "step start", -1, 1,
                                 std::string(what) + " set between steps"});
  }
}

void World::saveStepEnd() {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    step_start_[i] = {b.position, b.orientation, b.linear_velocity, b.angular_velocity};
  }
}

void World::restoreBody(size_t i) {
  Body& b = bodies_[i];
  b.position = step_start_[i].x;
  b.orientation = step_start_[i].q;
  b.linear_velocity.setZero();
  b.angular_velocity.setZero();
  b.force.setZero();
  b.torque.setZero();
  b.updateDerived();
}

void World::freezeIsland(std::int32_t island, size_t body, const char* stage, std::string detail) {
  int restored = 0;
  if (island < 0) {  // outside every island (kinematic): that body alone
    restoreBody(body);
    restored = 1;
  } else {
    frozen_island_[static_cast<size_t>(island)] = 1;
    any_frozen_ = true;
    for (size_t i = 0; i < bodies_.size(); ++i)
      if (body_island_[i] == island) ++restored;
  }
  numerical_events_.push_back({step_count_, BodyId{static_cast<std::int32_t>(body)}, bodies_[body].name, stage, island,
                               restored, std::move(detail)});
  holdFrozen();
}

// Keeps stopped islands at their step-start pose, at rest, with inert rows.
void World::holdFrozen() {
  if (!any_frozen_) return;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const std::int32_t isl = body_island_[i];
    if (isl >= 0 && frozen_island_[static_cast<size_t>(isl)]) restoreBody(i);
  }
  for (size_t isl = 0; isl < island_rows_.size() && isl < frozen_island_.size(); ++isl) {
    if (!frozen_island_[isl]) continue;
    for (std::int32_t k = island_rows_[isl].first; k < island_rows_[isl].second; ++k) {
      ConstraintRow& r = rows_[static_cast<size_t>(k)];
      ConstraintRow inert;  // J = 0, rhs = 0, lambda pinned to 0; cfm 1 keeps A_ii > 0 for every solver
      inert.body_a = r.body_a;
      inert.body_b = r.body_b;
      inert.kind = r.kind;
      inert.owner = r.owner;
      inert.owner_row = r.owner_row;
      inert.normal_row = r.normal_row;
      inert.cfm = 1;
      inert.inv_diag = 1;
      inert.lo = inert.hi = 0;
      r = inert;
    }
  }
}

void World::guardBodies(const char* stage) {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    const Body& b = bodies_[i];
    if (b.asleep || b.type == BodyType::Static || finiteState(b)) continue;
    const std::int32_t isl = body_island_[i];
    if (isl >= 0 && frozen_island_[static_cast<size_t>(isl)]) continue;  // already stopped: held below
    freezeIsland(isl, i, stage, badField(b));
  }
  holdFrozen();
}

// Called by solveRows right after an island's velocity solve, before the
// position-correction pass runs over every island's rows: a NaN born in the
// solve stops its island here, and the solver bodies it touched are reset
// (its own to rest, static and kinematic ones and the world to their
// velocities: 0 x inf = NaN would otherwise reach them through their zero
// inverse mass and, from them, the islands solved next).
void World::guardIslandSolve(std::int32_t begin, std::int32_t end) {
  const auto dynamicIndex = [&](std::int32_t solver_index) {
    return solver_index > 0 && bodies_[static_cast<size_t>(solver_index - 1)].isDynamic() ? solver_index - 1 : -1;
  };
  std::int32_t bad_body = -1;
  std::string detail;
  for (std::int32_t k = begin; k < end && bad_body < 0; ++k) {
    const ConstraintRow& r = rows_[static_cast<size_t>(k)];
    const char* field = badRowField(r);
    for (const std::int32_t si : {r.body_b, r.body_a}) {
      const std::int32_t bi = dynamicIndex(si);
      if (bi < 0) continue;
      const SolverBody& sb = solver_bodies_[static_cast<size_t>(si)];
      if (*field == 0 && sb.v.allFinite() && sb.w.allFinite()) continue;
      bad_body = bi;
      detail = r.kind >= RowKind::ContactNormal ? std::string("contact row")
                                                : "joint '" + joints_[static_cast<size_t>(r.owner)].def.name + "' row " +
                                                      std::to_string(r.owner_row);
      detail += *field == 0 ? std::string(": velocity not finite") : ": " + std::string(field) + " not finite";
      break;
    }
  }
  if (bad_body < 0) return;
  freezeIsland(body_island_[static_cast<size_t>(bad_body)], static_cast<size_t>(bad_body), "constraint solve", detail);
  for (std::int32_t k = begin; k < end; ++k) {
    const ConstraintRow& r = rows_[static_cast<size_t>(k)];
    for (const std::int32_t si : {r.body_a, r.body_b}) {
      SolverBody& sb = solver_bodies_[static_cast<size_t>(si)];
      sb = si == 0 ? SolverBody{} : SolverBody{bodies_[static_cast<size_t>(si - 1)].linear_velocity,
                                               bodies_[static_cast<size_t>(si - 1)].angular_velocity};
    }
  }
}

void World::guardRows(const char* stage) {
  for (size_t isl = 0; isl < island_rows_.size(); ++isl) {
    if (frozen_island_[isl]) continue;
    for (std::int32_t k = island_rows_[isl].first; k < island_rows_[isl].second; ++k) {
      const ConstraintRow& r = rows_[static_cast<size_t>(k)];
      const char* field = badRowField(r);
      if (*field == 0) continue;
      std::string what = r.kind >= RowKind::ContactNormal
                             ? std::string("contact row")
                             : "joint '" + joints_[static_cast<size_t>(r.owner)].def.name + "' row " +
                                   std::to_string(r.owner_row);
      // Name the row's body in this island (solver index = body index + 1).
      const auto inIsland = [&](std::int32_t solver_index) {
        return solver_index > 0 && body_island_[static_cast<size_t>(solver_index - 1)] == static_cast<std::int32_t>(isl);
      };
      const std::int32_t bi = inIsland(r.body_b) ? r.body_b - 1 : r.body_a - 1;
      freezeIsland(static_cast<std::int32_t>(isl), static_cast<size_t>(std::max(bi, 0)), stage,
                   what + ": " + std::string(field) + " not finite");
      break;
    }
  }
  holdFrozen();
}

}  // namespace cairn
