#include "solver/pgs.hpp"

#include <algorithm>
#include <cmath>

namespace cairn {

namespace {

// A sweep that moved no impulse by more than this fraction of the largest
// impulse has reached a fixed point to round-off (double precision keeps
// about 16 digits): further sweeps would repeat it, so the solve stops
// there. `iterations` is the most sweeps a solve makes.
constexpr Real kRoundOff = Real(1e-13);

// What a sweep gathers as it goes: the largest impulse, and for NNCG each
// row's change in this sweep (indexed like the rows) with their squared sum.
struct SweepTally {
  Real lambda_max = 0;
  Real* change = nullptr;  // null: not gathered (plain PGS)
  Real change_norm2 = 0;
  const ConstraintRow* first = nullptr;  // rows[0], to index `change`
  void add(const ConstraintRow& r, Real next, Real d) {
    lambda_max = std::max(lambda_max, std::abs(next));
    if (change) {
      change[&r - first] = d;
      change_norm2 += d * d;
    }
  }
};

inline Real rowVelocity(const ConstraintRow& r, const SolverBody& a, const SolverBody& b) {
  return r.j_lin_a.dot(a.v) + r.j_ang_a.dot(a.w) + r.j_lin_b.dot(b.v) + r.j_ang_b.dot(b.w);
}

inline void applyImpulse(const ConstraintRow& r, SolverBody& a, SolverBody& b, Real d) {
  a.v += r.m_lin_a * d;
  a.w += r.m_ang_a * d;
  b.v += r.m_lin_b * d;
  b.w += r.m_ang_b * d;
}

// splitmix64: a tiny, well-distributed generator whose sequence is fixed by
// the seed on every platform (std::shuffle's use of the engine is not
// specified across standard libraries).
inline std::uint64_t nextRandom(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Bounds of row i at this moment (friction: +-mu lambda_n of its normal row).
inline void rowBounds(const ConstraintRow& r, std::span<const ConstraintRow> rows, Real& lo, Real& hi) {
  lo = r.lo;
  hi = r.hi;
  if (r.normal_row >= 0) {
    hi = r.mu * rows[r.normal_row].lambda;
    lo = -hi;
  }
}

inline Real solveRow(ConstraintRow& r, std::span<ConstraintRow> rows, std::span<SolverBody> bodies, Real sor,
                     SweepTally& tally) {
  SolverBody& a = bodies[r.body_a];
  SolverBody& b = bodies[r.body_b];
  Real lo, hi;
  rowBounds(r, rows, lo, hi);
  const Real delta = (r.rhs - rowVelocity(r, a, b) - r.cfm * r.lambda) * r.inv_diag;
  const Real next = std::clamp(r.lambda + sor * delta, lo, hi);
  const Real d = next - r.lambda;
  r.lambda = next;
  applyImpulse(r, a, b, d);
  tally.add(r, next, d);
  return std::abs(d);
}

// A_ij = J_i M^-1 J_j^T for two rows on the same pair of bodies.
inline Real coupling(const ConstraintRow& i, const ConstraintRow& j) {
  return i.j_lin_a.dot(j.m_lin_a) + i.j_ang_a.dot(j.m_ang_a) + i.j_lin_b.dot(j.m_lin_b) + i.j_ang_b.dot(j.m_ang_b);
}

// Cholesky factor L (row-major, lower) of M = A_b + diag(cfm) + eps I.
// A face manifold's A_b is singular (4 coplanar points fix 3 motions);
// eps = 1e-12 of its largest diagonal makes M definite and picks, among the
// impulses that give the same motion, one of least norm.
inline void factorBlock(const Real* a_b, const ConstraintRow* r, int n, Real* l) {
  Real top = 0;
  for (int i = 0; i < n; ++i) top = std::max(top, a_b[i * n + i]);
  const Real eps = Real(1e-12) * top;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j <= i; ++j) {
      Real sum = a_b[i * n + j] + (i == j ? r[i].cfm + eps : Real(0));
      for (int k = 0; k < j; ++k) sum -= l[i * n + k] * l[j * n + k];
      l[i * n + j] = i == j ? std::sqrt(std::max(sum, eps)) : sum / l[j * n + j];
    }
    for (int j = i + 1; j < n; ++j) l[i * n + j] = 0;
  }
}

// One manifold's normal rows solved together, then one update of the two
// bodies. First the case of every point pushing (a resting face): one
// solve with the block's Cholesky factor, M delta = residual - cfm lambda,
// accepted when every impulse stays >= 0 and the rows' velocity errors
// vanish (to 1e-6 of the largest velocity error the block started with).
// Otherwise (a corner lifting, an impact) local projected sweeps on A_b
// until no row's velocity error exceeds that, at most 32; they cost a few
// flops each and touch no body.
inline Real solveBlock(ConstraintRow* r, int n, const Real* a_b, const Real* l, std::span<SolverBody> bodies, Real sor,
                       SweepTally& tally) {
  SolverBody& a = bodies[r[0].body_a];
  SolverBody& b = bodies[r[0].body_b];
  Real residual[4], lambda[4], delta[4] = {0, 0, 0, 0};
  Real scale = 0;
  for (int i = 0; i < n; ++i) {
    residual[i] = r[i].rhs - rowVelocity(r[i], a, b);  // target minus J v, before this block's change
    lambda[i] = r[i].lambda;
    scale = std::max(scale, std::abs(residual[i]));
  }
  const Real tol = Real(1e-6) * scale;

  // All points active: forward and back substitution with L.
  Real y[4];
  for (int i = 0; i < n; ++i) {
    Real sum = residual[i] - r[i].cfm * lambda[i];
    for (int k = 0; k < i; ++k) sum -= l[i * n + k] * y[k];
    y[i] = sum / l[i * n + i];
  }
  bool accept = true;
  for (int i = n - 1; i >= 0; --i) {
    Real sum = y[i];
    for (int k = i + 1; k < n; ++k) sum -= l[k * n + i] * delta[k];
    delta[i] = sum / l[i * n + i];
    accept = accept && lambda[i] + delta[i] >= r[i].lo;
  }
  for (int i = 0; i < n && accept; ++i) {  // the velocity errors with the true A_b
    Real w = residual[i] - r[i].cfm * (lambda[i] + delta[i]);
    for (int k = 0; k < n; ++k) w -= a_b[i * n + k] * delta[k];
    accept = std::abs(w) <= tol;
  }
  if (accept) {
    for (int i = 0; i < n; ++i) {
      const Real next = std::max(lambda[i] + sor * delta[i], r[i].lo);
      delta[i] = next - lambda[i];
      lambda[i] = next;
    }
  } else {
    for (int i = 0; i < n; ++i) delta[i] = 0;
    for (int sweep = 0; sweep < 32; ++sweep) {
      Real worst = 0;
      for (int i = 0; i < n; ++i) {
        Real jv = 0;  // A_b row i times this block's change so far
        for (int k = 0; k < n; ++k) jv += a_b[i * n + k] * delta[k];
        const Real w = residual[i] - jv - r[i].cfm * lambda[i];
        if (w > 0 || lambda[i] > r[i].lo) worst = std::max(worst, std::abs(w));
        const Real next = std::max(lambda[i] + sor * w * r[i].inv_diag, r[i].lo);
        delta[i] += next - lambda[i];
        lambda[i] = next;
      }
      if (worst <= tol) break;
    }
  }
  Real max_delta = 0;
  for (int i = 0; i < n; ++i) {
    r[i].lambda = lambda[i];
    applyImpulse(r[i], a, b, delta[i]);
    max_delta = std::max(max_delta, std::abs(delta[i]));
    tally.add(r[i], lambda[i], delta[i]);
  }
  return max_delta;
}

// Splits the rows into units: single rows, and blocks of 2 to 4 normal rows
// of the same manifold (consecutive, same owner), with their A_b.
void buildUnits(std::span<const ConstraintRow> rows, bool blocks, PgsScratch& s) {
  s.unit_begin.clear();
  s.block_of.clear();
  s.block.clear();
  for (size_t i = 0; i < rows.size();) {
    size_t j = i + 1;
    if (blocks && rows[i].kind == RowKind::ContactNormal)
      while (j < rows.size() && j - i < 4 && rows[j].kind == RowKind::ContactNormal && rows[j].owner == rows[i].owner &&
             rows[j].body_a == rows[i].body_a && rows[j].body_b == rows[i].body_b)
        ++j;
    s.unit_begin.push_back(static_cast<std::int32_t>(i));
    if (j - i > 1) {  // A_b, then its Cholesky factor
      const size_t at = s.block.size(), n = j - i;
      s.block_of.push_back(static_cast<std::int32_t>(at));
      for (size_t p = i; p < j; ++p)
        for (size_t q = i; q < j; ++q) s.block.push_back(coupling(rows[p], rows[q]));
      s.block.resize(at + 2 * n * n);
      factorBlock(&s.block[at], &rows[i], static_cast<int>(n), &s.block[at + n * n]);
    } else {
      s.block_of.push_back(-1);
    }
    i = j;
  }
  s.unit_begin.push_back(static_cast<std::int32_t>(rows.size()));  // sentinel
}

inline Real solveUnit(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, const PgsScratch& s, size_t u,
                      Real sor, SweepTally& tally) {
  const std::int32_t begin = s.unit_begin[u], end = s.unit_begin[u + 1];
  if (s.block_of[u] < 0) return solveRow(rows[static_cast<size_t>(begin)], rows, bodies, sor, tally);
  const int n = end - begin;
  const Real* a_b = &s.block[static_cast<size_t>(s.block_of[u])];
  return solveBlock(&rows[static_cast<size_t>(begin)], n, a_b, a_b + n * n, bodies, sor, tally);
}

// One sweep over the units, in order or shuffled; returns the largest change.
inline Real sweep(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, const PgsSettings& s,
                  PgsScratch& scratch, std::uint64_t& rng_state, SweepTally& tally) {
  Real max_delta = 0;
  const size_t units = scratch.block_of.size();
  if (s.randomize_order) {
    for (size_t i = units - 1; i > 0; --i)  // Fisher-Yates
      std::swap(scratch.order[i], scratch.order[nextRandom(rng_state) % (i + 1)]);
    for (std::int32_t u : scratch.order)
      max_delta = std::max(max_delta, solveUnit(rows, bodies, scratch, static_cast<size_t>(u), s.sor, tally));
  } else {
    for (size_t u = 0; u < units; ++u) max_delta = std::max(max_delta, solveUnit(rows, bodies, scratch, u, s.sor, tally));
  }
  return max_delta;
}

// The NNCG momentum step (Silcowitz, Niebe and Erleben 2010, "A nonsmooth
// nonlinear conjugate gradient method for interactive contact force
// problems", The Visual Computer 26): with d_k = lambda_k+1 - lambda_k the
// change of this sweep,
//     beta = |d_k|^2 / |d_k-1|^2,   restart (p = 0) when beta > 1,
//     lambda += beta p  (projected on the bounds),   p = beta p + d_k.
// Gauss-Seidel removes the error of a stiff chain (a stack, a heavy body on
// a light one) one link per sweep; the momentum carries the correction the
// sweeps keep making in the same direction (docs/constraints.md measures it).
inline void momentumStep(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, PgsScratch& s, Real norm2,
                         Real& prev_norm2) {
  const Real beta = prev_norm2 > 0 ? norm2 / prev_norm2 : Real(0);
  prev_norm2 = norm2;
  if (beta == 0 || beta > 1) {  // first sweep: p = d; beta > 1 (the sweeps stopped agreeing): restart, p = 0
    for (size_t i = 0; i < rows.size(); ++i) s.direction[i] = beta == 0 ? s.change[i] : Real(0);
    return;
  }
  for (size_t i = 0; i < rows.size(); ++i) {
    ConstraintRow& r = rows[i];
    Real lo, hi;
    rowBounds(r, rows, lo, hi);
    const Real next = std::clamp(r.lambda + beta * s.direction[i], lo, hi);
    const Real d = next - r.lambda;
    if (d != 0) {
      r.lambda = next;
      applyImpulse(r, bodies[r.body_a], bodies[r.body_b], d);
    }
    s.direction[i] = beta * s.direction[i] + s.change[i];
  }
}

}  // namespace

void applyWarmStart(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies) {
  for (const ConstraintRow& r : rows)
    if (r.lambda != 0) applyImpulse(r, bodies[r.body_a], bodies[r.body_b], r.lambda);
}

PgsStats solvePgs(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, const PgsSettings& s,
                  PgsScratch& scratch, std::uint64_t& rng_state) {
  PgsStats stats;
  if (rows.empty()) return stats;
  buildUnits(rows, s.manifold_blocks, scratch);
  const size_t units = scratch.block_of.size();
  if (s.randomize_order) {
    scratch.order.resize(units);
    for (size_t u = 0; u < units; ++u) scratch.order[u] = static_cast<std::int32_t>(u);
  }
  Real prev_norm2 = 0;
  if (s.nncg) {
    scratch.change.resize(rows.size());
    scratch.direction.assign(rows.size(), Real(0));
  }
  for (int it = 0; it < s.iterations; ++it) {
    SweepTally tally;
    tally.first = rows.data();
    if (s.nncg) tally.change = scratch.change.data();
    const Real max_delta = sweep(rows, bodies, s, scratch, rng_state, tally);
    const Real lambda_max = tally.lambda_max;
    stats.iterations = it + 1;
    stats.last_max_delta = max_delta;
    if (s.tolerance > 0 && max_delta <= s.tolerance) break;
    if (max_delta <= kRoundOff * lambda_max) break;  // a fixed point to round-off: more sweeps change nothing
    // No momentum after the last sweep: it would leave the rows unprojected
    // by a sweep (the result must be a PGS iterate).
    if (s.nncg && it + 1 < s.iterations) momentumStep(rows, bodies, scratch, tally.change_norm2, prev_norm2);
  }
  return stats;
}

bool solvePgsCorrection(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies, Correction which,
                        const PgsSettings& s, std::vector<Real>& lambda) {
  bool any = false;
  // Something to correct: a push (bias > 0), or a pull on a row that can
  // pull (lo < 0). A negative bias on a one-sided row only permits approach.
  for (const ConstraintRow& r : rows)
    any = any || (r.correction == which && (r.bias_rhs > 0 || (r.bias_rhs < 0 && r.lo < 0)));
  if (!any) return false;
  lambda.assign(rows.size(), 0);
  for (int it = 0; it < s.iterations; ++it) {
    Real max_delta = 0, lambda_max = 0;
    for (size_t i = 0; i < rows.size(); ++i) {
      const ConstraintRow& r = rows[i];
      if (r.correction != which) continue;
      SolverBody& a = bodies[r.body_a];
      SolverBody& b = bodies[r.body_b];
      const Real delta = (r.bias_rhs - rowVelocity(r, a, b) - r.cfm * lambda[i]) * r.inv_diag;
      const Real next = std::clamp(lambda[i] + s.sor * delta, r.lo, r.hi);
      const Real d = next - lambda[i];
      lambda[i] = next;
      applyImpulse(r, a, b, d);
      max_delta = std::max(max_delta, std::abs(d));
      lambda_max = std::max(lambda_max, std::abs(next));
    }
    if (s.tolerance > 0 && max_delta <= s.tolerance) break;
    if (max_delta <= kRoundOff * lambda_max) break;
  }
  return true;
}

}  // namespace cairn
