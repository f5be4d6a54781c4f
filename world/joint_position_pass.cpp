// Stage 7b of the step: the nonlinear joint position pass
// (solver/position_pass.hpp derives it; docs/extremes.md, "Heavy chains",
// measures it) for the islands solved directly or exactly. PGS islands do
// not get it: their sweeps leave errors of their own that a projection
// would hide, and their metrics report the joint error PGS leaves.
//
// The pass takes each rigid bilateral joint row (anchors, axes,
// orientations; CFM 0, unbounded) and drives its error to zero in
// positions. Limits, motors, soft joints and contacts keep their velocity
// rows only: a limit is unilateral, a motor has no position, a soft joint
// is a spring whose stretch is physics, and contacts have their own
// push-out (split impulse).
#include "solver/position_pass.hpp"
#include "world/position_pass_stage.hpp"

#include <algorithm>
#include <functional>

namespace cairn::detail {

namespace {

bool rigidBilateral(const ConstraintRow& r) {
  return (r.kind == RowKind::JointLinear || r.kind == RowKind::JointAngular) && r.cfm == 0 && r.lo == -kInf &&
         r.hi == kInf;
}

}  // namespace

void recordJointErrors(WorldImpl& w, StepContext& ctx) {
  ctx.joint_error_start.assign(w.joints_.size(), 0);
  if (w.settings_.position_iterations <= 0) return;
  const auto islandOf = [&](BodyId id) { return id.isWorld() ? -1 : ctx.body_island[static_cast<size_t>(id.index)]; };
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    const Joint& j = w.joints_[i];
    if (!j.alive || j.broken) continue;
    // Only the joints the pass may correct: PGS islands get no pass.
    const std::int32_t isl = std::max(islandOf(j.def.body_a), islandOf(j.def.body_b));
    if (isl < 0 || ctx.island_method[static_cast<size_t>(isl)] == SolverMethod::PGS) continue;
    ctx.joint_error_start[i] = measureJointError(j, w.view(j.def.body_a), w.view(j.def.body_b)).linear;
  }
}

void correctJointPositions(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  if (s.position_iterations <= 0 || ctx.island_count == 0) return;
  const auto corrected = [&](std::int32_t isl) {
    return isl >= 0 && ctx.island_method[static_cast<size_t>(isl)] != SolverMethod::PGS &&
           !(ctx.any_frozen && ctx.frozen_island[static_cast<size_t>(isl)]);
  };
  std::vector<std::int32_t>& joints = ctx.position_joints;
  joints.clear();
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    const Joint& j = w.joints_[i];
    if (!j.alive || j.broken || j.def.softness.isSet() || i >= ctx.joint_island.size() || !corrected(ctx.joint_island[i]))
      continue;
    // A joint that was apart by more than max_correction_velocity h when
    // the substep began is left to its velocity rows, which close it at
    // that capped speed (the safety net of docs/extremes.md); the pass
    // takes over for the last substep's worth.
    if (i < ctx.joint_error_start.size() && ctx.joint_error_start[i] > s.max_correction_velocity * ctx.hs) continue;
    joints.push_back(static_cast<std::int32_t>(i));
  }
  if (joints.empty()) return;

  const Real h = ctx.hs;
  const auto view = [&](BodyId id) {
    BodyView v = w.view(id);
    v.solver_index = id.isWorld() ? ctx.static_index : ctx.solver_of_body[static_cast<size_t>(id.index)];
    return v;
  };
  const auto build = [&](std::vector<ConstraintRow>& rows) {
    rows.clear();
    for (const std::int32_t ji : joints) {
      const Joint& j = w.joints_[static_cast<size_t>(ji)];
      RowContext rc;
      rc.h = h;
      rc.erp = 1;  // rhs = -C / h: the whole error in one Newton step
      rc.cfm = s.cfm;
      rc.joint_softness = &j.def.softness;
      rc.owner = ji;
      rc.rows = &rows;
      rc.correction = Correction::InRhs;
      // Built in place; the joint's rows that are not rigid and bilateral
      // (limits, motors) are dropped again (a ball or hinge joint has none).
      const auto first = static_cast<std::ptrdiff_t>(rows.size());
      buildJointRows(j, view(j.def.body_a), view(j.def.body_b), rc, JointRowSettings{s.restitution_threshold});
      rows.erase(std::remove_if(rows.begin() + first, rows.end(), [](const ConstraintRow& r) { return !rigidBilateral(r); }),
                 rows.end());
    }
  };
  const auto move = [&](std::span<const SolverBody> dx) {
    for (std::int32_t si = 1; si <= ctx.dynamic_count; ++si) {
      const size_t bi = static_cast<size_t>(ctx.body_of_solver[static_cast<size_t>(si)]);
      if (!corrected(ctx.body_island[bi])) continue;
      const SolverBody& d = dx[static_cast<size_t>(si)];
      if (d.v.squaredNorm() + d.w.squaredNorm() == 0) continue;
      Body& b = w.bodies_[bi];
      b.position += b.allowedLinear(d.v);
      b.orientation = (quatFromRotationVector(b.allowedAngular(d.w)) * b.orientation).normalized();
      b.updateDerived();
      // The velocity follows the corrected position, v = (x_{n+1} - x_n) / h
      // (position-based dynamics' update): a position moved without it
      // leaves a velocity that pulls the joint open again next step, and
      // on a whipping chain the two fight and pump energy in.
      b.linear_velocity += b.allowedLinear(d.v) / h;
      b.angular_velocity += b.allowedAngular(d.w) / h;
    }
  };
  ctx.position_bodies.resize(static_cast<size_t>(ctx.solver_count));
  PositionPassOptions o;
  o.max_iterations = s.position_iterations;
  o.h = h;
  // By reference: std::function keeps a reference_wrapper in place, where
  // a copy of either lambda would be allocated every substep.
  const PositionPassStats st =
      solvePositionPass(w.position_solver_, ctx.position_rows, ctx.position_bodies, std::ref(build), std::ref(move), o);
  w.stats_.position_iterations += st.iterations;
  w.stats_.position_error = std::max(w.stats_.position_error, st.error_after);
}

}  // namespace cairn::detail
