// The non-finite guard: no NaN leaves a step silently.
//
// ctx.step_start holds each body's last good state: taken at the end of
// every step and again at the start of the next (to keep what the API set
// in between). After each stage the guard looks for non-finite body states.
// The island it finds one in is stopped for the rest of the step: every
// awake dynamic body of it goes back to its step-start pose, at rest; later
// stages skip it (no constraints are prepared for it, nothing of it is
// stored for warm starting). Islands are solved apart and the solver never
// writes a static or kinematic body, so the other islands step exactly as
// if it were not there. One event per stopped island names the body, the
// stage and the island; after the solve the stage is "row building" when
// the island's prepared constraints held the non-finite number, else
// "constraint solve".
//
// Velocities are zeroed rather than restored: the restored island then has
// no more energy than at the step's start, and a blow-up driven by the
// velocity itself (a spin the integrator cannot take) is not replayed step
// after step; see docs/extremes.md.
#include "world/body_walk.hpp"
#include "world/step_stages.hpp"

#include <cmath>
#include <string>

namespace cairn::detail {

namespace {

// x - x is 0 for a finite x and NaN for an infinite or NaN one, so the
// thirteen numbers take one test (the guard runs on every moving body
// after every stage; badField names the culprit once one is found).
bool finiteState(const Body& b) {
  const Real zero = (b.position - b.position).sum() + (b.orientation.coeffs() - b.orientation.coeffs()).sum() +
                    (b.linear_velocity - b.linear_velocity).sum() + (b.angular_velocity - b.angular_velocity).sum();
  return zero == 0;
}

const char* badField(const Body& b) {
  if (!b.position.allFinite()) return "position";
  if (!b.orientation.coeffs().allFinite()) return "orientation";
  if (!b.linear_velocity.allFinite()) return "linear velocity";
  return "angular velocity";
}

// The first non-finite number the row was prepared with ("" when all are
// finite; the impulse, an output of the solve, is not looked at). Bounds
// may be infinite, never NaN.
const char* badRowField(const ConstraintRow& r) {
  const Real sum = r.rhs + r.bias_rhs + r.inv_diag + r.cfm + r.mu + r.j_lin_a.sum() + r.j_ang_a.sum() +
                   r.j_lin_b.sum() + r.j_ang_b.sum() + r.m_lin_a.sum() + r.m_ang_a.sum() + r.m_lin_b.sum() +
                   r.m_ang_b.sum();
  if (std::isfinite(sum) && !std::isnan(r.lo) && !std::isnan(r.hi)) return "";
  if (!std::isfinite(r.rhs)) return "rhs";
  if (!std::isfinite(r.bias_rhs)) return "position-correction target";
  if (!std::isfinite(r.inv_diag) || !std::isfinite(r.cfm)) return "effective mass";
  if (!(r.j_lin_a.allFinite() && r.j_ang_a.allFinite() && r.j_lin_b.allFinite() && r.j_ang_b.allFinite() &&
        r.m_lin_a.allFinite() && r.m_ang_a.allFinite() && r.m_lin_b.allFinite() && r.m_ang_b.allFinite()))
    return "Jacobian";
  if (std::isnan(r.lo) || std::isnan(r.hi) || std::isnan(r.mu)) return "bounds";
  return "";
}

// The first non-finite prepared number of one manifold lane ("" if none).
const char* badLaneField(const ContactBatch& b, int l) {
  Real sum = b.mu[l] + b.cfm[l];
  for (int k = 0; k < 3; ++k) sum += b.n[k][l] + b.ma[k][l] + b.mb[k][l];
  for (int k = 0; k < 6; ++k) sum += b.ia[k][l] + b.ib[k][l];
  for (int k = 0; k < 10; ++k) sum += b.block[k][l] + b.factor[k][l];
  for (int k = 0; k < 3; ++k) sum += b.patch_mass[k][l];
  sum += b.twist_mass[l];
  Real point = 0;
  for (int i = 0; i < kMaxPoints; ++i) {
    const ContactBatch::Point& p = b.p[i];
    for (int k = 0; k < 3; ++k)
      point += p.ran[k][l] + p.rbn[k][l] + p.t[k][l] + p.ra[k][l] + p.rb[k][l];
    point += p.rhs[l] + p.bias[l] + p.normal_mass[l] + p.tangent_mass[0][l] + p.tangent_mass[1][l] + b.arm[i][l];
  }
  if (!std::isfinite(point)) return "anchor, target or effective mass";
  if (!std::isfinite(sum)) return "mass data, normal or block";
  return "";
}

void restoreBody(WorldImpl& w, StepContext& ctx, size_t i) {
  Body& b = w.bodies_[i];
  b.position = ctx.step_start[i].x;
  b.orientation = ctx.step_start[i].q;
  b.linear_velocity.setZero();
  b.angular_velocity.setZero();
  b.force.setZero();
  b.torque.setZero();
  b.updateDerived();
}

// Keeps stopped islands at their step-start pose, at rest.
void holdFrozen(WorldImpl& w, StepContext& ctx) {
  if (!ctx.any_frozen) return;
  for (size_t i = 0; i < w.bodies_.size(); ++i) {
    const std::int32_t isl = ctx.body_island[i];
    if (isl >= 0 && ctx.frozen_island[static_cast<size_t>(isl)]) restoreBody(w, ctx, i);
  }
}

void freezeIsland(WorldImpl& w, StepContext& ctx, std::int32_t island, size_t body, const char* stage,
                  std::string detail) {
  int restored = 0;
  if (island < 0) {  // outside every island (kinematic): that body alone
    restoreBody(w, ctx, body);
    restored = 1;
  } else {
    ctx.frozen_island[static_cast<size_t>(island)] = 1;
    ctx.any_frozen = true;
    for (size_t i = 0; i < w.bodies_.size(); ++i)
      if (ctx.body_island[i] == island) ++restored;
  }
  w.numerical_events_.push_back({w.step_count_, w.bodyId(static_cast<int>(body)), w.bodies_[body].name, stage, island,
                                 restored, std::move(detail)});
  holdFrozen(w, ctx);
}

// What in the island's prepared constraints is non-finite, if anything.
std::string badConstraint(const WorldImpl& w, const StepContext& ctx, std::int32_t island) {
  const GraphProblem& g = ctx.graph;
  for (size_t bi = 0; bi < g.batches.size(); ++bi)
    for (int l = 0; l < kBatchLanes; ++l) {
      const ContactBatch& b = g.batches[bi];
      if (b.count[l] == 0 || b.island[l] != island) continue;
      const char* f = badLaneField(b, l);
      if (*f) return std::string("contact: ") + f + " not finite";
    }
  const auto rowText = [&](const ConstraintRow& r) {
    return r.kind >= RowKind::ContactNormal
               ? std::string("contact row")
               : "joint '" + w.joints_[static_cast<size_t>(r.owner)].def.name + "' row " + std::to_string(r.owner_row);
  };
  for (const RowGroup& grp : g.groups) {
    if (grp.island != island) continue;
    for (std::int32_t k = grp.begin; k < grp.end; ++k) {
      const ConstraintRow& r = g.rows[static_cast<size_t>(k)];
      const char* f = badRowField(r);
      if (*f) return rowText(r) + ": " + f + " not finite";
    }
  }
  if (static_cast<size_t>(island) < ctx.island_rows.size()) {
    const auto [begin, end] = ctx.island_rows[static_cast<size_t>(island)];
    for (std::int32_t k = begin; k < end; ++k) {
      const ConstraintRow& r = ctx.rows[static_cast<size_t>(k)];
      const char* f = badRowField(r);
      if (*f) return rowText(r) + ": " + f + " not finite";
    }
  }
  return "";
}

// Names a row of the island whose body went non-finite in the solve.
std::string solveCulprit(const WorldImpl& w, const StepContext& ctx, std::int32_t island) {
  const auto bad = [&](std::int32_t si) {
    const SolverBody& v = ctx.velocities[static_cast<size_t>(si)];
    return si > 0 && !(v.v.allFinite() && v.w.allFinite());
  };
  for (const RowGroup& grp : ctx.graph.groups) {
    if (grp.island != island) continue;
    for (std::int32_t k = grp.begin; k < grp.end; ++k) {
      const ConstraintRow& r = ctx.graph.rows[static_cast<size_t>(k)];
      if (!bad(r.body_a) && !bad(r.body_b)) continue;
      if (r.kind >= RowKind::ContactNormal) return "contact row: velocity not finite";
      return "joint '" + w.joints_[static_cast<size_t>(r.owner)].def.name + "' row " + std::to_string(r.owner_row) +
             ": velocity not finite";
    }
  }
  return "contact: velocity not finite";
}

}  // namespace

// A destroyed body's records go with it: its slot may be reused by a body
// that must not inherit them, and a program that spawns and removes bodies
// for hours must not collect a record for each.
void WorldImpl::dropDiagnosticsOf(BodyId id) {
  if (diagnostic_last_step_.size() < diagnostics_.size()) diagnostic_last_step_.resize(diagnostics_.size(), -1);
  size_t kept = 0;
  for (size_t i = 0; i < diagnostics_.size(); ++i) {
    if (diagnostics_[i].body.index == id.index) continue;
    if (kept != i) {  // a record moved onto itself would lose its strings (a moved-from string is empty)
      diagnostics_[kept] = std::move(diagnostics_[i]);
      diagnostic_last_step_[kept] = diagnostic_last_step_[i];
    }
    ++kept;
  }
  diagnostics_.resize(kept);
  diagnostic_last_step_.resize(kept);
  diagnostic_index_.invalidate();
}

void WorldImpl::diagnose(std::int32_t body, const char* kind, const std::string& detail, bool once_per_step) {
  // A restored snapshot brings its diagnostics but not the step each was
  // last counted in.
  if (diagnostic_last_step_.size() < diagnostics_.size()) diagnostic_last_step_.resize(diagnostics_.size(), -1);
  if (const std::int32_t at = diagnostic_index_.find(diagnostics_, body, kind); at >= 0) {
    const auto i = static_cast<size_t>(at);
    if (once_per_step && diagnostic_last_step_[i] == step_count_) return;
    Diagnostic& d = diagnostics_[i];
    ++d.count;
    diagnostic_last_step_[i] = step_count_;
    d.detail = detail;  // the latest figures
    return;
  }
  diagnostic_last_step_.push_back(step_count_);
  if (body < 0) diagnostics_.push_back({kWorldBody, "world", kind, detail, step_count_, 1});
  else diagnostics_.push_back({bodyId(body), bodies_[static_cast<size_t>(body)].name, kind, detail, step_count_, 1});
  diagnostic_index_.add(body, diagnostics_.back().kind, static_cast<std::int32_t>(diagnostics_.size()) - 1);
}

// The guards' walks read every moving body after each stage: on the pool's
// threads (world/body_walk.hpp; with the watchers' walks, the 5,050-box
// pyramid's guards stage on two threads went from 1.95 to 1.78 ms a step,
// docs/performance.md). What they find is handled after, in body order, on
// the calling thread.
void saveStepStart(WorldImpl& w, StepContext& ctx) {
  ctx.step_start.resize(w.bodies_.size());
  ctx.start_energy.resize(w.bodies_.size());
  // T + V as the step begins. At rest (every sleeping body) T is +0 to the
  // bit, without reading the body's rotation and inertia.
  const auto startEnergy = [&](size_t i) {
    const Body& b = w.bodies_[i];
    Real e = 0;
    if (b.alive && b.isDynamic()) {
      const bool rest = b.linear_velocity == Vec3::Zero() && b.angular_velocity == Vec3::Zero();
      e = (rest ? Real(0) : b.kineticEnergy()) - b.mass * w.gravity_.dot(b.position);
    }
    ctx.start_energy[i] = e;
  };
  const bool any_bad = anyBody(w, [&](size_t i) {
    const Body& b = w.bodies_[i];
    if (b.alive && !finiteState(b)) return true;  // handled below, after the walk
    if (b.alive) ctx.step_start[i] = {b.position, b.orientation, b.linear_velocity, b.angular_velocity, b.asleep};
    startEnergy(i);
    return false;
  });
  if (!any_bad) return;
  for (size_t i = 0; i < w.bodies_.size(); ++i) {
    Body& b = w.bodies_[i];
    if (!b.alive || finiteState(b)) continue;
    // Set through the API since the last step: back to the last good
    // state, at rest. Its island has not moved yet, so this body alone
    // is restored.
    const char* what = badField(b);
    restoreBody(w, ctx, i);
    w.numerical_events_.push_back({w.step_count_, w.bodyId(static_cast<int>(i)), b.name, "step start", -1, 1,
                                   std::string(what) + " set between steps"});
    startEnergy(i);
  }
}

// Only a body that could move has a new state to save (StepContext::moves).
void saveStepEnd(WorldImpl& w, StepContext& ctx) {
  anyBody(w, [&](size_t i) {
    const Body& b = w.bodies_[i];
    if (ctx.moves(i) && b.alive) ctx.step_start[i] = {b.position, b.orientation, b.linear_velocity, b.angular_velocity, b.asleep};
    return false;
  });
}

void guardBodies(WorldImpl& w, StepContext& ctx, const char* stage) {
  // Only a body that could move (unchanged since saveStepStart found it
  // finite otherwise).
  const auto bad = [&](size_t i) {
    if (!ctx.moves(i)) return false;
    const Body& b = w.bodies_[i];
    return b.alive && !b.asleep && b.type != BodyType::Static && !finiteState(b);
  };
  handleFound(w, bad, [&](size_t i) {
    const std::int32_t isl = ctx.body_island[i];
    if (isl >= 0 && ctx.frozen_island[static_cast<size_t>(isl)]) return;  // already stopped: held below
    freezeIsland(w, ctx, isl, i, stage, badField(w.bodies_[i]));
  });
  holdFrozen(w, ctx);
}

void guardSolve(WorldImpl& w, StepContext& ctx) {
  const auto bad = [&](size_t i) {
    const std::int32_t isl = ctx.body_island[i];
    if (isl < 0) return false;
    const Body& b = w.bodies_[i];
    return b.alive && !ctx.frozen_island[static_cast<size_t>(isl)] && !finiteState(b);
  };
  handleFound(w, bad, [&](size_t i) {  // bad() reads frozen_island again: a freeze stops the rest of its island
    const std::int32_t isl = ctx.body_island[i];
    const std::string row = badConstraint(w, ctx, isl);
    if (!row.empty()) freezeIsland(w, ctx, isl, i, "row building", row);
    else freezeIsland(w, ctx, isl, i, "constraint solve", solveCulprit(w, ctx, isl));
  });
  holdFrozen(w, ctx);
}

}  // namespace cairn::detail
