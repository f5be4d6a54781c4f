// Stages 6, 8 and 9 of the step: the velocity solve (PGS over the coloured
// constraint graph for PGS islands, a direct factor or exact pivoting island by
// island for the others) and the position-correction passes; the impulses
// kept for warm starting, joint feedback and breaking; restitution.
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/step_stages.hpp"

#include <algorithm>
#include <cmath>

namespace cairn::detail {

const ContactKernels& contactKernelsFor(const SolverSettings& s) {
  const SimdLevel level = s.simd == Simd::Portable ? SimdLevel::Portable
                          : s.simd == Simd::Avx2   ? SimdLevel::Avx2
                          : s.simd == Simd::Avx512 ? SimdLevel::Avx512
                                                   : bestSimdLevel();
  return contactKernels(level);
}

namespace {

GraphSolveOptions graphOptions(WorldImpl& w, const StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  GraphSolveOptions o;
  o.iterations = s.iterations;
  o.tolerance = s.tolerance;
  o.sor = s.sor;
  o.friction_rows = s.friction_directions;
  o.patch_friction = s.patch_friction;
  o.nncg = s.nncg;
  o.randomize_order = s.randomize_order;
  o.dynamic_end = ctx.dynamic_count + 1;
  o.kernels = &contactKernelsFor(s);
  o.pool = w.pool_.get();
  return o;
}

// The solved velocities back into the bodies (awake dynamic, not stopped).
void writeBack(WorldImpl& w, StepContext& ctx) {
  for (std::int32_t si = 1; si <= ctx.dynamic_count; ++si) {
    const size_t bi = static_cast<size_t>(ctx.body_of_solver[static_cast<size_t>(si)]);
    const std::int32_t isl = ctx.body_island[bi];
    if (ctx.any_frozen && ctx.frozen_island[static_cast<size_t>(isl)]) continue;
    Body& b = w.bodies_[bi];
    b.linear_velocity = ctx.velocities[static_cast<size_t>(si)].v;
    b.angular_velocity = ctx.velocities[static_cast<size_t>(si)].w;
  }
}

// A manifold lane's row: direction u, angular parts (ra x u, rb x u).
struct LaneRow {
  Vec3 u, ra_u, rb_u;
};

// row 0: normal, 1, 2: tangents, 3: a patch's twist (solver/contact_batch.hpp)
LaneRow laneRowParts(const ContactBatch& b, int l, int i, int row) {
  const ContactBatch::Point& q = b.p[i];
  const auto v3 = [&](const double (*f)[kBatchLanes]) { return Vec3(f[0][l], f[1][l], f[2][l]); };
  const Vec3 n = v3(b.n);
  if (row == 0) return {n, v3(q.ran), v3(q.rbn)};
  if (row == 3) return {Vec3::Zero(), n, n};
  const Vec3 t1 = v3(q.t);
  const Vec3 u = row == 1 ? t1 : Vec3(n.cross(t1));
  return {u, v3(q.ra).cross(u), v3(q.rb).cross(u)};  // as the kernels form them
}

// The natural-map residual of the manifolds (solver/lcp_residual.hpp's
// definition, with the velocities after the solve): per row
// |lambda - clamp(lambda - w, lo, hi)|, w = J v - rhs + cfm lambda; for a
// friction patch the pair's |l - proj_disc(l - w)| and the twist row's.
Real manifoldResidual(const GraphProblem& g, std::span<const SolverBody> v, bool patch) {
  Real worst = 0;
  for (const ContactBatch& b : g.batches)
    for (int l = 0; l < kBatchLanes; ++l) {
      if (b.count[l] == 0) continue;
      const SolverBody& a = v[static_cast<size_t>(b.body_a[l])];
      const SolverBody& c = v[static_cast<size_t>(b.body_b[l])];
      const auto jv = [&](const LaneRow& r) { return r.u.dot(c.v - a.v) + r.rb_u.dot(c.w) - r.ra_u.dot(a.w); };
      for (int i = 0; i < b.count[l]; ++i) {
        const ContactBatch::Point& q = b.p[i];
        if (q.valid[l] == 0) continue;
        const Real cfm = b.cfm[l];
        const Real ln = q.lambda[l];
        const Real wn = jv(laneRowParts(b, l, i, 0)) - q.rhs[l] + cfm * ln;
        worst = std::max(worst, std::abs(ln - std::max(ln - wn, Real(0))));
        if (b.mu[l] <= 0) continue;
        if (patch) continue;
        const Real bound = b.mu[l] * ln;
        for (int k = 0; k < 2; ++k) {
          if (q.tangent_mass[k][l] == 0) continue;  // no such row
          const Real lt = q.lambda_t[k][l];
          const Real wt = jv(laneRowParts(b, l, i, 1 + k)) + cfm * lt;
          worst = std::max(worst, std::abs(lt - std::clamp(lt - wt, -bound, bound)));
        }
      }
      if (!patch || b.mu[l] <= 0 || b.p[0].tangent_mass[0][l] == 0) continue;
      Real load = 0, twist_load = 0;
      for (int i = 0; i < b.count[l]; ++i) {
        load += b.p[i].lambda[l];
        twist_load += b.p[i].lambda[l] * b.arm[i][l];
      }
      const Real cfm = b.cfm[l];
      const ContactBatch::Point& q = b.p[0];
      const Eigen::Vector2d lt(q.lambda_t[0][l], q.lambda_t[1][l]);
      const Eigen::Vector2d wt(jv(laneRowParts(b, l, 0, 1)) + cfm * lt[0], jv(laneRowParts(b, l, 0, 2)) + cfm * lt[1]);
      Eigen::Vector2d x = lt - wt;
      const Real limit = b.mu[l] * load;
      if (x.norm() > limit) x *= limit / x.norm();
      worst = std::max(worst, (lt - x).cwiseAbs().maxCoeff());
      if (b.twist_mass[l] == 0) continue;
      const Vec3 n(b.n[0][l], b.n[1][l], b.n[2][l]);
      const Real tw = b.lambda_twist[l];
      const Real wtw = n.dot(c.w - a.w) + cfm * tw;
      const Real tlimit = b.mu[l] * twist_load;
      worst = std::max(worst, std::abs(tw - std::clamp(tw - wtw, -tlimit, tlimit)));
    }
  return worst;
}

void storeJointRow(WorldImpl& w, const ConstraintRow& r, Real h) {
  if (r.owner < 0 || r.kind >= RowKind::ContactNormal) return;
  Joint& j = w.joints_[static_cast<size_t>(r.owner)];
  j.warm[static_cast<size_t>(r.owner_row)] = r.lambda;
  const Real f = r.lambda / h;
  j.feedback.force_a += r.j_lin_a * f;
  j.feedback.torque_a += r.j_ang_a * f;
  j.feedback.force_b += r.j_lin_b * f;
  j.feedback.torque_b += r.j_ang_b * f;
}

}  // namespace

void solveConstraints(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  if (!w.rng_seeded_) {
    w.rng_state_ = s.seed;
    w.rng_seeded_ = true;
  }
  const GraphSolveOptions o = graphOptions(w, ctx);
  std::span<SolverBody> v(ctx.velocities);
  Real residual = 0;

  // PGS islands, all at once over the coloured graph; the contacts'
  // split-impulse correction with them where it can be (graph_solver.hpp).
  std::fill(ctx.pseudo.begin(), ctx.pseudo.end(), SolverBody{});
  if (!ctx.graph.empty()) {
    const GraphSolveStats st = solveGraph(ctx.graph, v, o, w.rng_state_, ctx.pseudo);
    w.stats_.iterations += st.iterations;
    if (s.compute_residual) {
      residual = std::max(residual, manifoldResidual(ctx.graph, v, s.patch_friction));
      for (const RowGroup& grp : ctx.graph.groups)
        residual = std::max(residual,
                            lcpResidual(std::span<const ConstraintRow>(ctx.graph.rows).subspan(
                                            static_cast<size_t>(grp.begin), static_cast<size_t>(grp.end - grp.begin)),
                                        v));
    }
  }
  // The other islands, one by one.
  int other_iterations = 0;
  for (std::int32_t isl = 0; isl < ctx.island_count; ++isl) {
    const auto [begin, end] = ctx.island_rows[static_cast<size_t>(isl)];
    if (end == begin) continue;
    std::span<ConstraintRow> rows(ctx.rows.data() + begin, static_cast<size_t>(end - begin));
    if (ctx.island_method[static_cast<size_t>(isl)] == SolverMethod::Direct) {
      // A sparse factor for the bilateral rows (linear in a tree of joints,
      // else CHOLMOD), PGS sweeps for the bounded ones,
      // alternated (solver/direct_solver.hpp); warm-started from lambda.
      DirectSolverOptions d;
      d.inner_pgs_iterations = s.iterations;
      d.warm_start = s.warm_start;
      d.report_residual = false;  // measured below when compute_residual asks
      const DirectSolveStats st = w.direct_solver_.solve(rows, v, d);
      other_iterations = std::max(other_iterations, st.outer_iterations);
    } else {
      // Dantzig pivoting to the exact mixed-LCP solution (small islands).
      const ExactLcpResult st = w.exact_solver_.solve(rows, v);
      other_iterations = std::max(other_iterations, st.pivots);
    }
    if (s.compute_residual) residual = std::max(residual, lcpResidual(rows, v));
  }
  w.stats_.iterations += other_iterations;
  w.stats_.residual = residual;

  // Position correction in its own passes (constraints/row.hpp,
  // Correction): Baumgarte's bias velocities join the state; split
  // impulse's pseudo-velocities move the bodies this step but add no
  // momentum or kinetic energy.
  ctx.has_pseudo = solveGraphCorrection(ctx.graph, v, ctx.pseudo, o);
  if (!ctx.rows.empty()) {
    PgsSettings ps{s.iterations, s.tolerance, s.sor, false, s.seed};
    solvePgsCorrection(ctx.rows, v, Correction::VelocityBias, ps, ctx.correction_lambda);
    ctx.has_pseudo =
        solvePgsCorrection(ctx.rows, ctx.pseudo, Correction::PseudoVelocity, ps, ctx.correction_lambda) || ctx.has_pseudo;
  }
  writeBack(w, ctx);
}

void applyRestitution(WorldImpl& w, StepContext& ctx) {
  bool any = false;
  for (const ContactBatch& b : ctx.graph.batches)
    for (int i = 0; i < kMaxPoints && !any; ++i)
      for (int l = 0; l < kBatchLanes; ++l) any = any || b.p[i].bounce[l] != 0;
  if (!any) return;
  // The velocities may have changed since the solve (the guard): start
  // from the bodies'.
  for (std::int32_t si = 1; si <= ctx.dynamic_count; ++si) {
    const Body& b = w.bodies_[static_cast<size_t>(ctx.body_of_solver[static_cast<size_t>(si)])];
    ctx.velocities[static_cast<size_t>(si)] = SolverBody{b.linear_velocity, b.angular_velocity};
  }
  solveGraphRestitution(ctx.graph, ctx.velocities, graphOptions(w, ctx));
  writeBack(w, ctx);
}

namespace {

// An island whose constraints were not solved this substep: none (-1), or
// one a guard stopped.
bool stoppedIsland(const StepContext& ctx, std::int32_t isl) {
  return isl < 0 || (ctx.any_frozen && ctx.frozen_island[static_cast<size_t>(isl)]);
}

// Patch friction (solver/contact_batch.hpp): the patch's tangent impulse P
// and twist impulse T shared out over its points as friction impulses with
// the same sum and the same moment about the normal at the centre c,
//   f_i = P / k + T (n x d_i) / sum_j |d_j|^2,   d_i = r_a,i - c in the plane,
// over its k points with a normal row (sum_i n x d_i = 0, as c is their
// mean). The contact reports them per point as with per-point friction,
// and the fill reads P = sum f_i and T = sum n . (d_i x f_i) back. With
// n x d_i = mean_j (r_a,j x n) - r_a,i x n the split needs only the
// normal rows' angular parts.
void splitPatch(Contact& c, const ContactBatch& b, int l, const Vec3& patch) {  // patch: P
  const auto ran = [&](int i) { return Vec3(b.p[i].ran[0][l], b.p[i].ran[1][l], b.p[i].ran[2][l]); };
  int k = 0;
  Vec3 mean = Vec3::Zero();
  Real arm2 = 0;
  for (int i = 0; i < c.count; ++i) {
    if (b.p[i].valid[l] == 0) continue;
    ++k;
    mean += ran(i);
    arm2 += b.arm[i][l] * b.arm[i][l];
  }
  if (k == 0) {  // no normal row: no friction either
    for (int i = 0; i < c.count; ++i) c.points[i].friction_impulse.setZero();
    return;
  }
  mean /= Real(k);
  const Real twist = arm2 > 0 ? b.lambda_twist[l] / arm2 : Real(0);
  for (int i = 0; i < c.count; ++i)
    c.points[i].friction_impulse = b.p[i].valid[l] == 0 ? Vec3::Zero() : Vec3(patch / Real(k) + (mean - ran(i)) * twist);
}

// One manifold lane's impulses back into its contact (nothing for padding
// or a stopped island).
void storeLane(WorldImpl& w, const StepContext& ctx, size_t slot) {
  const std::int32_t ci = ctx.lane_contact[slot];
  if (ci < 0) return;
  const ContactBatch& b = ctx.graph.batches[slot / kBatchLanes];
  const int l = static_cast<int>(slot % kBatchLanes);
  if (stoppedIsland(ctx, b.island[l])) return;
  Contact& c = w.contacts_[static_cast<size_t>(ci)];
  // A point's tangent pair (t1, n x t1) as one world vector; with patch
  // friction point 0's pair is the patch's.
  const auto tangentImpulse = [&](const ContactBatch::Point& q) {
    const Vec3 t1(q.t[0][l], q.t[1][l], q.t[2][l]);
    return Vec3(t1 * q.lambda_t[0][l] + c.normal.cross(t1) * q.lambda_t[1][l]);
  };
  const bool patch = w.settings_.patch_friction;
  for (int i = 0; i < c.count; ++i) {
    const ContactBatch::Point& q = b.p[i];
    ContactPointState& p = c.points[i];
    p.normal_impulse = q.lambda[l];
    p.max_impulse = std::max(p.max_impulse, q.max_lambda[l]);
    if (!patch) p.friction_impulse = tangentImpulse(q);
  }
  if (patch) splitPatch(c, b, l, tangentImpulse(b.p[0]));
}

}  // namespace

void storeLaneImpulses(WorldImpl& w, StepContext& ctx) {
  // Each lane writes its own contact (on the pool's threads when there are
  // many).
  const auto storeLanes = [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      // The contact a batch ahead, while this one is written.
      if (k + kBatchLanes < end) prefetchLaneContact(w, ctx, static_cast<size_t>(k + kBatchLanes));
      storeLane(w, ctx, static_cast<size_t>(k));
    }
  };
  const int slots = static_cast<int>(ctx.lane_contact.size());
  if (w.pool_ && slots >= kParallelLanes) w.pool_->parallelFor(slots, storeLanes);
  else storeLanes(0, slots);
  ctx.lanes_unstored = false;
}

void storeImpulses(WorldImpl& w, StepContext& ctx) {
  const Real h = ctx.hs;
  for (Joint& j : w.joints_) {
    std::fill(j.warm.begin(), j.warm.end(), Real(0));
    j.feedback = JointFeedback{};
  }
  // Row groups: joints, and contacts with rolling friction.
  const GraphProblem& g = ctx.graph;
  for (size_t gi = 0; gi < g.groups.size(); ++gi) {
    const RowGroup& grp = g.groups[gi];
    if (stoppedIsland(ctx, grp.island)) continue;
    const std::int32_t owner = ctx.group_joint[gi];
    if (owner >= 0) {
      for (std::int32_t k = grp.begin; k < grp.end; ++k) storeJointRow(w, g.rows[static_cast<size_t>(k)], h);
    } else {
      storeContactImpulses(w.contacts_[static_cast<size_t>(-1 - owner)], g.rows);
    }
  }
  // Manifold lanes: after the last substep, and after every substep where
  // each prepares its contacts anew. Refreshed lanes carry their impulses
  // into the next substep instead, and the cache catches up after the last
  // one, or in prepareConstraints before it prepares any lane anew.
  if (ctx.substep + 1 == w.settings_.substeps || w.settings_.prepare_contacts_each_substep) storeLaneImpulses(w, ctx);
  else ctx.lanes_unstored = true;
  // Generic rows of the other islands.
  for (const ConstraintRow& r : ctx.rows) storeJointRow(w, r, h);
  for (size_t ci = 0; ci < w.contacts_.size(); ++ci) {
    const std::int32_t isl = ctx.contact_island[ci];
    if (!stoppedIsland(ctx, isl) && ctx.island_method[static_cast<size_t>(isl)] != SolverMethod::PGS)
      storeContactImpulses(w.contacts_[ci], ctx.rows);
  }
  // Joints that break: force or torque past the threshold.
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    Joint& j = w.joints_[i];
    if (!j.alive || j.broken) continue;
    if (j.def.break_force == kInf && j.def.break_torque == kInf) continue;  // unbreakable (the default)
    const Real force = j.feedback.force_b.norm();
    // Torque about the anchor on b: remove the moment of the force about b's center.
    const BodyView bv = w.view(j.def.body_b);
    const Vec3 anchor_b = worldPoint(bv, j.local_anchor_b);
    const Real torque = (j.feedback.torque_b - (anchor_b - bv.x).cross(j.feedback.force_b)).norm();
    if (force > j.def.break_force || torque > j.def.break_torque) {
      const JointId id = w.jointId(static_cast<int>(i));
      w.break_events_.push_back({w.step_count_, id, j.def.name, force, torque});
      w.removeJoint(id);
    }
  }
}

}  // namespace cairn::detail

namespace cairn::detail {

namespace {

// A manifold lane's row at point i (row 0: normal, 1, 2: tangents) in the
// generic form.
ConstraintRow laneRow(const ContactBatch& b, int l, int i, int row, Real inv_diag, RowKind kind) {
  const LaneRow parts = laneRowParts(b, l, i, row);
  const Vec3 ma(b.ma[0][l], b.ma[1][l], b.ma[2][l]), mb(b.mb[0][l], b.mb[1][l], b.mb[2][l]);
  const auto sym = [&](const double (*m)[kBatchLanes]) {
    Mat3 r;
    r << m[0][l], m[3][l], m[4][l], m[3][l], m[1][l], m[5][l], m[4][l], m[5][l], m[2][l];
    return r;
  };
  ConstraintRow r;
  r.j_lin_a = -parts.u;
  r.j_ang_a = -parts.ra_u;
  r.j_lin_b = parts.u;
  r.j_ang_b = parts.rb_u;
  r.m_lin_a = ma.cwiseProduct(r.j_lin_a);
  r.m_ang_a = sym(b.ia) * r.j_ang_a;
  r.m_lin_b = mb.cwiseProduct(r.j_lin_b);
  r.m_ang_b = sym(b.ib) * r.j_ang_b;
  r.inv_diag = inv_diag;
  r.cfm = b.cfm[l];
  r.kind = kind;
  r.owner_row = static_cast<std::int8_t>(i);
  return r;
}

}  // namespace

// Every row of the last (sub)step, island by island in the generic form
// and numbering the exact solvers and the tests read: a body's index is its
// slot + 1, the world (and every static body) 0; a friction row's
// normal_row counts from its island's first row.
std::vector<ConstraintRow> WorldImpl::expandedRows() const {
  const StepContext& ctx = ctx_;
  const GraphProblem& g = ctx.graph;
  const auto remap = [&](std::int32_t si) {
    return si > 0 ? ctx.body_of_solver[static_cast<size_t>(si)] + 1 : 0;
  };
  std::vector<ConstraintRow> out;
  for (std::int32_t isl = 0; isl < ctx.island_count; ++isl) {
    const auto begin = static_cast<std::int32_t>(out.size());
    const auto [rb, re] = static_cast<size_t>(isl) < ctx.island_rows.size() ? ctx.island_rows[static_cast<size_t>(isl)]
                                                                              : std::pair<std::int32_t, std::int32_t>{0, 0};
    for (std::int32_t k = rb; k < re; ++k) {
      ConstraintRow r = ctx.rows[static_cast<size_t>(k)];
      r.body_a = remap(r.body_a);
      r.body_b = remap(r.body_b);
      out.push_back(r);
    }
    for (const RowGroup& grp : g.groups) {
      if (grp.island != isl) continue;
      const auto at = static_cast<std::int32_t>(out.size());
      for (std::int32_t k = grp.begin; k < grp.end; ++k) {
        ConstraintRow r = g.rows[static_cast<size_t>(k)];
        r.body_a = remap(r.body_a);
        r.body_b = remap(r.body_b);
        if (r.normal_row >= 0) r.normal_row += at - begin;
        out.push_back(r);
      }
    }
    // Manifolds: their normal rows, then their friction rows.
    std::vector<std::pair<size_t, int>> lanes;
    for (size_t bi = 0; bi < g.batches.size(); ++bi)
      for (int l = 0; l < kBatchLanes; ++l)
        if (g.batches[bi].count[l] > 0 && g.batches[bi].island[l] == isl) lanes.emplace_back(bi, l);
    std::vector<std::int32_t> normal_at;
    for (const auto& [bi, l] : lanes) {
      const ContactBatch& b = g.batches[bi];
      for (int i = 0; i < kMaxPoints; ++i) {
        normal_at.push_back(-1);
        if (i >= b.count[l] || b.p[i].valid[l] == 0) continue;
        ConstraintRow r = laneRow(b, l, i, 0, b.p[i].normal_mass[l], RowKind::ContactNormal);
        r.body_a = remap(b.body_a[l]);
        r.body_b = remap(b.body_b[l]);
        r.rhs = b.p[i].rhs[l];
        r.bias_rhs = b.p[i].bias[l];
        r.correction = settings_.split_impulse ? Correction::PseudoVelocity : settings_.position_correction;
        r.lambda = b.p[i].lambda[l];
        r.lo = 0;
        r.owner = ctx.lane_contact[bi * kBatchLanes + static_cast<size_t>(l)];
        normal_at.back() = static_cast<std::int32_t>(out.size()) - begin;
        out.push_back(r);
      }
    }
    size_t point = 0;
    for (const auto& [bi, l] : lanes) {
      const ContactBatch& b = g.batches[bi];
      for (int i = 0; i < kMaxPoints; ++i, ++point) {
        if (normal_at[point] < 0 || b.mu[l] <= 0) continue;
        for (int k = 0; k < 2; ++k) {
          if (b.p[i].tangent_mass[k][l] == 0) continue;  // no such row
          ConstraintRow r = laneRow(b, l, i, 1 + k, b.p[i].tangent_mass[k][l], RowKind::ContactFriction);
          r.body_a = remap(b.body_a[l]);
          r.body_b = remap(b.body_b[l]);
          r.lambda = b.p[i].lambda_t[k][l];
          r.mu = b.mu[l];
          r.normal_row = normal_at[point];
          r.owner = ctx.lane_contact[bi * kBatchLanes + static_cast<size_t>(l)];
          r.owner_row = static_cast<std::int8_t>(4 + 2 * i + k);
          out.push_back(r);
        }
        if (i > 0 || b.twist_mass[l] == 0) continue;
        // A friction patch's twist row (its rows' bounds are the patch's,
        // not mu times normal_row's impulse: the exact solvers do not take
        // them, validation/lcp_probe.cpp).
        ConstraintRow r = laneRow(b, l, 0, 3, b.twist_mass[l], RowKind::ContactFriction);
        r.body_a = remap(b.body_a[l]);
        r.body_b = remap(b.body_b[l]);
        r.lambda = b.lambda_twist[l];
        r.mu = b.mu[l];
        r.normal_row = normal_at[point];
        r.owner = ctx.lane_contact[bi * kBatchLanes + static_cast<size_t>(l)];
        r.owner_row = 12;
        out.push_back(r);
      }
    }
  }
  return out;
}

}  // namespace cairn::detail
