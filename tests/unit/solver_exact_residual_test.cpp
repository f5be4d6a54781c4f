// The natural-map residual computed from rows and velocities.
#include "solver/dense_system.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"
#include "solver_exact_fixtures.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using exact_test::RowSystem;

RowSystem contactScene(std::mt19937& rng) {
  RowSystem s = exact_test::rigidChain(4, rng);
  for (int b = 1; b <= 4; ++b) {
    s.bodies[static_cast<std::size_t>(b)].v += Vec3(0.3, -1.0, 0.0);  // falling and sliding
    s.addContact(b, exact_test::randomVec(rng, 0.4), Vec3(0, 1, 0), 0.5, 0.01);
  }
  for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-4);
  return s;
}

// The residual reads w from the velocities, the dense definition from A
// and b; with v = v* + M^-1 J^T lambda they are the same numbers up to
// round-off (1e-12 on O(1) impulses and velocities), for impulses inside,
// on and outside their bounds.
TEST(Residual, MatchesDenseNaturalMap) {
  std::mt19937 rng(21);
  RowSystem s = contactScene(rng);
  const DenseLcp lcp = assembleDenseLcp(s.rows, s.bodies);
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    s.rows[i].lambda = exact_test::uniform(rng, -1, 2);
    applyRowImpulse(s.rows[i], s.rows[i].lambda, s.bodies);
  }
  const Eigen::VectorXd lambda = s.lambdaVector();
  const Eigen::VectorXd w = lcp.A * lambda + lcp.b;
  Real max_f = 0, sum = 0;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    Real lo = lcp.lo(i), hi = lcp.hi(i);
    if (lcp.normal_row[static_cast<std::size_t>(i)] >= 0) {
      hi = std::abs(lcp.mu(i) * lambda(lcp.normal_row[static_cast<std::size_t>(i)]));
      lo = -hi;
    }
    // mid(lambda - lo, lambda - hi, w): the median form of the same map.
    const Real a = lambda(i) - lo, b = lambda(i) - hi, c = w(i);
    const Real f = std::max(std::min(a, b), std::min(std::max(a, b), c));
    max_f = std::max(max_f, std::abs(f));
    sum += f * f;
  }
  const LcpResidualReport rep = lcpResidualReport(s.rows, s.bodies);
  EXPECT_NEAR(rep.max_norm, max_f, 1e-12);
  EXPECT_NEAR(rep.two_norm, std::sqrt(sum), 1e-12);
  EXPECT_GT(rep.max_norm, 0.1);  // random impulses are far from a solution
  EXPECT_EQ(lcpResidual(s.rows, s.bodies, ResidualNorm::Max), rep.max_norm);
  EXPECT_EQ(lcpResidual(s.rows, s.bodies, ResidualNorm::Two), rep.two_norm);
}

// Zero (to the exact solver's round-off) at the exact solution; a
// perturbation delta of one impulse, applied consistently to the
// velocities, moves that row's entry of the map by about
// min(1, A_ii + cfm) delta (its lambda moves by delta, its w by
// (A_ii + cfm) delta), and A_ii >= 1/3 here (masses <= 3 kg): so > delta / 10.
TEST(Residual, ZeroAtExactSolutionPositiveWhenPerturbed) {
  std::mt19937 rng(22);
  RowSystem s = contactScene(rng);
  const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
  ASSERT_TRUE(res.converged);
  EXPECT_LE(lcpResidual(s.rows, s.bodies, ResidualNorm::Max), 1e-10);
  EXPECT_LE(lcpResidual(s.rows, s.bodies, ResidualNorm::Two), 1e-10);
  EXPECT_EQ(res.residual, lcpResidual(s.rows, s.bodies, ResidualNorm::Max));

  for (std::size_t i : {std::size_t(0), std::size_t(12), std::size_t(14)}) {
    RowSystem p = s;
    const Real delta = 1e-3;
    p.rows[i].lambda += delta;
    applyRowImpulse(p.rows[i], delta, p.bodies);
    const LcpResidualReport rep = lcpResidualReport(p.rows, p.bodies);
    EXPECT_GT(rep.max_norm, 0.1 * delta) << "row " << i;
    EXPECT_GE(rep.two_norm, rep.max_norm);
  }
}

// Friction rows take -+ mu |lambda_normal|: the same friction impulse is a
// solution inside a wide cone and violates a narrow one.
TEST(Residual, FrictionBoundsFollowTheNormalImpulse) {
  RowSystem s;
  const int b = s.addBody(1, Mat3::Identity(), Vec3(0, 0, 0.2));
  const int normal = s.addContact(b, Vec3::Zero(), Vec3(0, 1, 0), 0.5, 0);
  s.rows.resize(2);  // one friction row (tangent -z) is enough
  ConstraintRow& f = s.rows[1];
  ASSERT_EQ(f.normal_row, normal);
  // Choose lambda_f so the row sticks: A_ff = 1, so w_f = slip + lambda_f = 0.
  const Real slip = rowJv(f, s.bodies);
  ASSERT_NEAR(std::abs(slip), 0.2, 1e-15);
  f.lambda = -slip;
  applyRowImpulse(f, f.lambda, s.bodies);
  s.rows[0].lambda = 1.0;  // normal impulse along y: does not touch the tangent
  applyRowImpulse(s.rows[0], 1.0, s.bodies);
  ASSERT_NEAR(rowJv(f, s.bodies), 0.0, 1e-15);
  // Row 0's own entry: w_0 = 1 (A_00 = 1), lambda_0 = 1 in [0, inf) -> F_0 = 1.
  // Only the friction entry is examined here.
  auto frictionEntry = [&](Real mu) {
    s.rows[1].mu = mu;
    const auto [lo, hi] = lcpRowBounds(s.rows, 1);
    return std::abs(naturalMap(f.lambda, rowJv(f, s.bodies) + f.cfm * f.lambda, lo, hi));
  };
  EXPECT_EQ(frictionEntry(1.0), 0.0);                         // |lambda_f| = |slip| = 0.2 <= 1.0 * 1
  EXPECT_NEAR(frictionEntry(0.05), std::abs(slip) - 0.05, 1e-15);  // clamped to 0.05: off by 0.15
}

TEST(Residual, LambdaDistanceIsRelative) {
  EXPECT_EQ(lambdaDistance({}, {}), 0.0);
  EXPECT_EQ(lambdaDistance({0, 0}, {0, 0}), 0.0);
  EXPECT_EQ(lambdaDistance({1, 2}, {1, 2, 3}), std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(lambdaDistance({3, 4}, {3, 4.5}), 0.5 / std::sqrt(3 * 3 + 4.5 * 4.5));
  // Scale-free: the same relative change at 1e6 and at 1 (to round-off of 1 + 1e-6).
  EXPECT_NEAR(lambdaDistance({1e6, 0}, {1e6 + 1, 0}), lambdaDistance({1, 0}, {1 + 1e-6, 0}), 1e-15);
  EXPECT_EQ(lambdaDistance({1, 0}, {0, 0}), 1.0);
}

}  // namespace
}  // namespace cairn
