#include "validation/lcp_probe.hpp"

#include "dynamics/integrate.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>

namespace cairn::validation {

namespace {

// The condition under which solvePgsCorrection (solver/pgs.cpp) runs its
// Baumgarte pass, which changes the velocities after the solve.
bool correctionPassRan(const std::vector<ConstraintRow>& rows) {
  return std::any_of(rows.begin(), rows.end(), [](const ConstraintRow& r) {
    return r.correction == Correction::VelocityBias && (r.bias_rhs > 0 || (r.bias_rhs < 0 && r.lo < 0));
  });
}

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[size_t(i)] != i) i = parent[size_t(i)] = parent[size_t(parent[size_t(i)])];
    return i;
  }
  void unite(int a, int b) { parent[size_t(find(a))] = find(b); }
};

// |J^T x|_M^-1 = sqrt(p^T M^-1 p) with p = J^T x the bodies' impulse: the
// sum over bodies of p . (M^-1 p), M^-1 J^T being cached on each row.
template <class Impulse>
double kineticNorm(const std::vector<ConstraintRow>& rows, size_t body_count, Impulse x) {
  std::vector<SolverBody> p(body_count + 1), dv(body_count + 1);
  for (size_t i = 0; i < rows.size(); ++i) {
    const ConstraintRow& r = rows[i];
    const Real l = Real(x(i));
    p[size_t(r.body_a)].v += r.j_lin_a * l;
    p[size_t(r.body_a)].w += r.j_ang_a * l;
    dv[size_t(r.body_a)].v += r.m_lin_a * l;
    dv[size_t(r.body_a)].w += r.m_ang_a * l;
    p[size_t(r.body_b)].v += r.j_lin_b * l;
    p[size_t(r.body_b)].w += r.j_ang_b * l;
    dv[size_t(r.body_b)].v += r.m_lin_b * l;
    dv[size_t(r.body_b)].w += r.m_ang_b * l;
  }
  double e = 0;
  for (size_t k = 1; k < p.size(); ++k) e += p[k].v.dot(dv[k].v) + p[k].w.dot(dv[k].w);  // 0 is the world
  return std::sqrt(std::max(e, 0.0));
}

}  // namespace

void ExactLcpProbe::beforeStep(const World& world) { before_ = cairn::detail::internals(world).bodies(); }

std::optional<ExactLcpProbe::Distance> ExactLcpProbe::afterStep(const World& world, Real h) {
  const std::vector<ConstraintRow>& rows = cairn::detail::internals(world).expandedRows();
  const std::vector<Body>& bodies = cairn::detail::internals(world).bodies();
  why_.clear();
  if (rows.empty()) {
    why_ = "the step solved no rows";
    return std::nullopt;
  }
  if (world.settings().patch_friction) {
    why_ = "friction per patch: its disc and twist bounds are not the exact solver's friction model";
    return std::nullopt;
  }
  if (world.settings().sleeping && world.lastStepStats().sleeping_bodies > 0) {
    why_ = "bodies fell asleep (their velocities were zeroed after the solve)";
    return std::nullopt;
  }

  // v*: solver body 0 is the world, body i is i + 1 (world/world_step.cpp).
  std::vector<SolverBody> v(bodies.size() + 1);
  if (!correctionPassRan(rows)) {
    for (size_t i = 0; i < bodies.size(); ++i) v[i + 1] = {bodies[i].linear_velocity, bodies[i].angular_velocity};
    for (const ConstraintRow& r : rows) {
      if (r.body_a > 0) {
        v[size_t(r.body_a)].v -= r.m_lin_a * r.lambda;
        v[size_t(r.body_a)].w -= r.m_ang_a * r.lambda;
      }
      if (r.body_b > 0) {
        v[size_t(r.body_b)].v -= r.m_lin_b * r.lambda;
        v[size_t(r.body_b)].w -= r.m_ang_b * r.lambda;
      }
    }
  } else {
    if (world.settings().substeps != 1) {
      why_ = "PGS's Baumgarte pass with several substeps: v* of the last substep is not recoverable";
      return std::nullopt;
    }
    if (!cairn::detail::internals(world).springs().empty()) {
      why_ = "springs add forces inside the step";
      return std::nullopt;
    }
    if (before_.size() != bodies.size()) {
      why_ = "no state kept before the step";
      return std::nullopt;
    }
    for (size_t i = 0; i < bodies.size(); ++i) {
      Body b = before_[i];
      if (!b.asleep) {
        (void)integrateVelocity(b, world.gravity(), h, world.settings().gyroscopic);
        // The World's spin cap, applied right after (world_step.cpp).
        const Real w = b.angular_velocity.norm();
        if (w > world.settings().max_angular_velocity) b.angular_velocity *= world.settings().max_angular_velocity / w;
      }
      v[i + 1] = {b.linear_velocity, b.angular_velocity};
    }
  }

  // Islands: rows are built island by island (a contiguous range each) and
  // a friction row's normal_row counts from its island's first row, so the
  // exact solver must see one island at a time. An island is a connected
  // set of dynamic bodies.
  const auto dynamic = [&](int s) { return s > 0 && bodies[size_t(s - 1)].isDynamic(); };
  UnionFind uf(bodies.size() + 1);
  for (const ConstraintRow& r : rows)
    if (dynamic(r.body_a) && dynamic(r.body_b)) uf.unite(r.body_a, r.body_b);
  const auto island = [&](const ConstraintRow& r) { return uf.find(dynamic(r.body_a) ? r.body_a : r.body_b); };

  std::vector<ConstraintRow> exact = rows;
  size_t begin = 0;
  for (size_t i = 1; i <= rows.size(); ++i) {
    if (i < rows.size() && island(rows[i]) == island(rows[begin])) continue;
    const size_t n = i - begin;
    if (n > size_t(max_rows_)) {
      why_ = "an island of " + std::to_string(n) + " rows (the exact solver is used up to " +
             std::to_string(max_rows_) + ")";
      return std::nullopt;
    }
    // A friction row must find its own contact's normal row in the range,
    // or the ranges are not the World's islands.
    for (size_t k = begin; k < i; ++k) {
      const ConstraintRow& r = rows[k];
      if (r.normal_row < 0) continue;
      const size_t nr = begin + size_t(r.normal_row);
      if (nr >= i || rows[nr].owner != r.owner || rows[nr].kind != RowKind::ContactNormal) {
        why_ = "the rows' islands could not be told apart";
        return std::nullopt;
      }
    }
    const ExactLcpResult st = solveLcpExact(std::span<ConstraintRow>(exact.data() + begin, n), v);
    if (!st.converged) {
      // Measured on column-10 with two substeps: the pivoting cycles on a
      // resting stack's redundant contacts (2500 pivots, the limit) where
      // the World's own solve of the same rows, from v* differing by
      // round-off, converged. No reference, no figure.
      why_ = "the exact solver did not converge (" + std::to_string(st.pivots) + " pivots, residual " +
             std::to_string(st.residual) + ")";
      return std::nullopt;
    }
    begin = i;
  }
  Distance d;
  d.lambda = lambdaDistance(rowLambdas(rows), rowLambdas(exact));
  const double moved = kineticNorm(rows, bodies.size(), [&](size_t i) { return double(rows[i].lambda); });
  const double moved_exact = kineticNorm(rows, bodies.size(), [&](size_t i) { return double(exact[i].lambda); });
  const double apart = kineticNorm(rows, bodies.size(), [&](size_t i) { return double(rows[i].lambda - exact[i].lambda); });
  const double scale = std::max(moved, moved_exact);
  d.velocity = scale > 0 ? apart / scale : 0;
  return d;
}

}  // namespace cairn::validation
