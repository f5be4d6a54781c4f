// The joints' lane kernels (joint_lanes.hpp), written once for any vector
// width W with the contact kernels' vector helpers: included by
// contact_kernel_impl.hpp into each instruction set's unit, under the same
// rules (no function shared with other units, no contraction).
//
// Per lane and row, the scalar row update of graph_solver.cpp's solveGroup
// in the same order of operations:
//
//   delta   = (rhs - J v - cfm lambda) / (A_ii + cfm)
//   lambda' = clamp(lambda + sor delta, lo, hi)
//   v      += M^-1 J^T (lambda' - lambda)     (writable bodies only)
//
// The lanes' bodies stay in registers from the group's first row to its
// last: row k + 1 sees row k's update, as it does solved alone.
#pragma once

template <int W>
struct JointKernel : Kernel<W> {
  using K = Kernel<W>;
  using D = typename K::D;
  using M = typename K::M;
  using V3 = typename K::V3;

  // v + m d where `write`, else v: M^-1 J^T d added to a writable body.
  CAIRN_INLINE V3 addIf(M write, const V3& v, const double (*m)[kBatchLanes], int o, D d) {
    return K::sel3(write, K::add(v, K::mul(K::ld3(m, o), d)), v);
  }
  // The lanes in use whose island still sweeps (all in use, without
  // island_active).
  static inline M usedLanes(const JointLanes& lane, int o, const double* island_active) {
    D on = K::ld(lane.used + o);
    if (island_active)
      for (int i = 0; i < W; ++i) on[i] = on[i] > 0 && island_active[lane.island[o + i]] > 0 ? 1 : 0;
    return on > 0;
  }
  // Which lanes of `active` write their body (the plan's flags).
  static inline M writes(const double* flags, int o, M active) { return active & (K::ld(flags + o) > 0); }

  // One visit of lanes [o, o + W) of `lane` on the velocities `bodies`,
  // from the impulses `impulse` toward the targets `target`, of the rows
  // whose correction is `which` (all rows when which < 0): the velocity
  // pass and the correction passes differ only in these and in what the
  // velocity pass records, which `record(row, change, row in use)` does.
  using RowLanes = JointLaneRow::Lanes JointLaneRow::*;
  template <class Record>
  CAIRN_INLINE void visit(JointLanes& lane, JointLaneRow* rows, int o, double* bodies, const ContactSweepParams& p,
                          RowLanes impulse, RowLanes target, double which, Record&& record) {
    const M active = usedLanes(lane, o, p.island_active);
    if (!K::any(active)) return;
    const D sor = K::splat(p.sor);
    const M write_a = writes(lane.writes_a, o, active);
    const M write_b = writes(lane.writes_b, o, active);
    V3 va, wa, vb, wb;
    K::gather1(bodies, lane.body_a + o, va, wa);
    K::gather1(bodies, lane.body_b + o, vb, wb);
    D maxd = K::zero(), maxl = K::zero();
    for (int k = 0; k < lane.rows; ++k) {
      JointLaneRow& r = rows[lane.row_begin + k];
      M on = active;
      if (which >= 0) on &= (K::ld(r.correction + o) == K::splat(which));
      if (!K::any(on)) continue;
      const D jv = K::dot(K::ld3(r.j_lin_a, o), va) + K::dot(K::ld3(r.j_ang_a, o), wa) +
                   K::dot(K::ld3(r.j_lin_b, o), vb) + K::dot(K::ld3(r.j_ang_b, o), wb);
      const D lam = K::ld((r.*impulse) + o);
      const D delta = (K::ld((r.*target) + o) - jv - K::ld(r.cfm + o) * lam) * K::ld(r.inv_diag + o);
      const D x = lam + sor * delta;
      const D lo = K::ld(r.lo + o), hi = K::ld(r.hi + o);
      const D next = x < lo ? lo : (hi < x ? hi : x);  // std::clamp's order of tests
      const D d = K::sel(on, next - lam, K::zero());
      K::st((r.*impulse) + o, K::sel(on, next, lam));
      record(r, d, on);
      va = addIf(on & write_a, va, r.m_lin_a, o, d);
      wa = addIf(on & write_a, wa, r.m_ang_a, o, d);
      vb = addIf(on & write_b, vb, r.m_lin_b, o, d);
      wb = addIf(on & write_b, wb, r.m_ang_b, o, d);
      // std::max(m, |x|) keeps m unless m < |x|, as vmax(|x|, m) does.
      maxd = K::vmax(K::vabs(d), maxd);
      maxl = K::vmax(K::vabs(K::sel(on, next, K::zero())), maxl);
    }
    K::scatter1(bodies, lane.body_a + o, va, wa, p.dynamic_end, active);
    K::scatter1(bodies, lane.body_b + o, vb, wb, p.dynamic_end, active);
    K::st(lane.delta + o, maxd);
    K::st(lane.lambda + o, maxl);
  }

  static void solveLanes(JointLanes* lanes, JointLaneRow* rows, int begin, int end, double* bodies,
                         const ContactSweepParams& p) {
    for (int li = begin; li < end; ++li)
      for (int o = 0; o < kBatchLanes; o += W)
        visit(lanes[li], rows, o, bodies, p, &JointLaneRow::lambda, &JointLaneRow::rhs, -1,
              [&](JointLaneRow& r, D d, M on) {
                if (p.gather_change) K::st(r.change + o, K::sel(on, d, K::ld(r.change + o)));
              });
  }

  // A correction pass's visit: the rows whose correction is `which`,
  // toward their bias targets from lambda_bias.
  static void biasLanes(JointLanes* lanes, JointLaneRow* rows, int begin, int end, double* bodies, int which,
                        const ContactSweepParams& p) {
    for (int li = begin; li < end; ++li)
      for (int o = 0; o < kBatchLanes; o += W)
        visit(lanes[li], rows, o, bodies, p, &JointLaneRow::lambda_bias, &JointLaneRow::bias_rhs, which,
              [](JointLaneRow&, D, M) {});
  }

  // NNCG's momentum step on the lanes, as graph_solver.cpp's groupMomentum
  // per joint: with its island's beta, lambda += beta p clamped to the
  // bounds (applied only where it moved), then p = beta p + change; beta
  // == 0 sets p = change, beta > 1 restarts with p = 0, beta < 0 (the
  // island has stopped) leaves the joint as it is.
  static void momentumLanes(JointLanes* lanes, JointLaneRow* rows, int begin, int end, double* bodies,
                            const double* island_beta, const ContactSweepParams& p) {
    for (int li = begin; li < end; ++li) {
      JointLanes& lane = lanes[li];
      for (int o = 0; o < kBatchLanes; o += W) {
        D beta = K::splat(-1);  // an unused lane is left as it is, as a stopped island's
        for (int i = 0; i < W; ++i)
          if (lane.group[o + i] >= 0) beta[i] = island_beta[lane.island[o + i]];
        const M run = beta >= 0;
        if (!K::any(run)) continue;
        const M restart = run & ((beta == 0) | (beta > 1));
        const M step = run & ~restart;
        const bool steps = K::any(step);
        const M write_a = writes(lane.writes_a, o, step);
        const M write_b = writes(lane.writes_b, o, step);
        V3 va, wa, vb, wb;
        if (steps) {
          K::gather1(bodies, lane.body_a + o, va, wa);
          K::gather1(bodies, lane.body_b + o, vb, wb);
        }
        for (int k = 0; k < lane.rows; ++k) {
          JointLaneRow& r = rows[lane.row_begin + k];
          const D dir = K::ld(r.dir + o), change = K::ld(r.change + o);
          if (steps) {
            const D lam = K::ld(r.lambda + o);
            const D x = lam + beta * dir;
            const D lo = K::ld(r.lo + o), hi = K::ld(r.hi + o);
            const D next = x < lo ? lo : (hi < x ? hi : x);
            const D d = next - lam;
            const M moved = step & (d != 0);
            K::st(r.lambda + o, K::sel(moved, next, lam));
            va = addIf(moved & write_a, va, r.m_lin_a, o, d);
            wa = addIf(moved & write_a, wa, r.m_ang_a, o, d);
            vb = addIf(moved & write_b, vb, r.m_lin_b, o, d);
            wb = addIf(moved & write_b, wb, r.m_ang_b, o, d);
          }
          const D restarted = K::sel(beta == 0, change, K::zero());
          K::st(r.dir + o, K::sel(restart, restarted, K::sel(step, beta * dir + change, dir)));
        }
        if (steps) {
          K::scatter1(bodies, lane.body_a + o, va, wa, p.dynamic_end, step);
          K::scatter1(bodies, lane.body_b + o, vb, wb, p.dynamic_end, step);
        }
      }
    }
  }
};
