#include "solver/lcp_residual.hpp"

#include "solver/dense_system.hpp"

#include <limits>

namespace cairn {

LcpResidualReport lcpResidualReport(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies) {
  LcpResidualReport rep;
  Real sum = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const ConstraintRow& r = rows[i];
    const auto [lo, hi] = lcpRowBounds(rows, i);
    const Real w = rowJv(r, bodies) - r.rhs + r.cfm * r.lambda;
    const Real f = std::abs(naturalMap(r.lambda, w, lo, hi));
    sum += f * f;
    // A NaN entry wins and sticks, so a broken row is the one reported.
    if (rep.worst_row < 0 || f > rep.max_norm || (std::isnan(f) && !std::isnan(rep.max_norm))) {
      rep.max_norm = f;
      rep.worst_row = static_cast<int>(i);
    }
  }
  rep.two_norm = std::sqrt(sum);
  return rep;
}

Real lcpResidual(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies, ResidualNorm norm) {
  const LcpResidualReport rep = lcpResidualReport(rows, bodies);
  return norm == ResidualNorm::Max ? rep.max_norm : rep.two_norm;
}

double lambdaDistance(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double diff = 0, na = 0, nb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff += (a[i] - b[i]) * (a[i] - b[i]);
    na += a[i] * a[i];
    nb += b[i] * b[i];
  }
  const double scale = std::sqrt(std::max(na, nb));
  if (scale == 0) return 0;
  return std::sqrt(diff) / scale;
}

std::vector<double> rowLambdas(std::span<const ConstraintRow> rows) {
  std::vector<double> out(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) out[i] = rows[i].lambda;
  return out;
}

}  // namespace cairn
