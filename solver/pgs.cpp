#include "solver/pgs.hpp"

#include <algorithm>
#include <cmath>

namespace cairn {

namespace {

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

inline Real solveRow(ConstraintRow& r, std::span<ConstraintRow> rows, std::span<SolverBody> bodies, Real sor) {
  SolverBody& a = bodies[r.body_a];
  SolverBody& b = bodies[r.body_b];
  Real lo = r.lo, hi = r.hi;
  if (r.normal_row >= 0) {
    hi = r.mu * rows[r.normal_row].lambda;
    lo = -hi;
  }
  const Real delta = (r.rhs - rowVelocity(r, a, b) - r.cfm * r.lambda) * r.inv_diag;
  const Real next = std::clamp(r.lambda + sor * delta, lo, hi);
  const Real d = next - r.lambda;
  r.lambda = next;
  applyImpulse(r, a, b, d);
  return std::abs(d);
}

}  // namespace

void applyWarmStart(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies) {
  for (const ConstraintRow& r : rows)
    if (r.lambda != 0) applyImpulse(r, bodies[r.body_a], bodies[r.body_b], r.lambda);
}

PgsStats solvePgs(std::span<ConstraintRow> rows, std::span<SolverBody> bodies, const PgsSettings& s,
                  std::vector<std::int32_t>& order, std::uint64_t& rng_state) {
  PgsStats stats;
  const auto n = static_cast<std::int32_t>(rows.size());
  if (n == 0) return stats;
  if (s.randomize_order) {
    order.resize(static_cast<size_t>(n));
    for (std::int32_t i = 0; i < n; ++i) order[static_cast<size_t>(i)] = i;
  }
  for (int it = 0; it < s.iterations; ++it) {
    Real max_delta = 0;
    if (s.randomize_order) {
      for (std::int32_t i = n - 1; i > 0; --i)  // Fisher-Yates
        std::swap(order[static_cast<size_t>(i)], order[nextRandom(rng_state) % static_cast<std::uint64_t>(i + 1)]);
      for (std::int32_t i : order) max_delta = std::max(max_delta, solveRow(rows[static_cast<size_t>(i)], rows, bodies, s.sor));
    } else {
      for (ConstraintRow& r : rows) max_delta = std::max(max_delta, solveRow(r, rows, bodies, s.sor));
    }
    stats.iterations = it + 1;
    stats.last_max_delta = max_delta;
    if (s.tolerance > 0 && max_delta <= s.tolerance) break;
  }
  return stats;
}

bool solvePgsCorrection(std::span<const ConstraintRow> rows, std::span<SolverBody> bodies, Correction which,
                        const PgsSettings& s, std::vector<Real>& lambda) {
  bool any = false;
  for (const ConstraintRow& r : rows) any = any || (r.correction == which && r.bias_rhs != 0);
  if (!any) return false;
  lambda.assign(rows.size(), 0);
  for (int it = 0; it < s.iterations; ++it) {
    Real max_delta = 0;
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
    }
    if (s.tolerance > 0 && max_delta <= s.tolerance) break;
  }
  return true;
}

Real pgsResidual(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies) {
  // Natural map F_i = lambda_i - clamp(lambda_i - w_i, lo_i, hi_i) with
  // w_i = J_i v - rhs_i + cfm_i lambda_i; zero exactly at an LCP solution.
  Real res = 0;
  for (const ConstraintRow& r : rows) {
    Real lo = r.lo, hi = r.hi;
    if (r.normal_row >= 0) {
      hi = r.mu * rows[static_cast<size_t>(r.normal_row)].lambda;
      lo = -hi;
    }
    const Real w = rowVelocity(r, bodies[r.body_a], bodies[r.body_b]) - r.rhs + r.cfm * r.lambda;
    res = std::max(res, std::abs(r.lambda - std::clamp(r.lambda - w, lo, hi)));
  }
  return res;
}

}  // namespace cairn
