// The CHOLMOD direct solver: exact on bilateral rows, block Gauss-Seidel
// with PGS on the others, symbolic analysis reuse, regularization.
#include "solver/dense_system.hpp"
#include "solver/direct_solver.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"
#include "solver_exact_fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace cairn {
namespace {

using exact_test::RowSystem;
using exact_test::uniform;
using exact_test::velocityMismatch;

DirectSolverOptions coldOptions(int outer, int inner) {
  DirectSolverOptions o;
  o.outer_iterations = outer;
  o.inner_pgs_iterations = inner;
  o.warm_start = false;
  return o;
}

// Bilateral rows only: one CHOLMOD solve is the exact answer. The three
// answers (sparse Cholesky, Dantzig's pivoting, Eigen's dense LDLT) differ
// by round-off amplified by cond(A) < 1e4 for these chains: 1e-9 relative
// leaves a wide margin.
TEST(DirectSolver, BilateralRowsMatchExactSolverAndDenseLdlt) {
  std::mt19937 rng(41);
  for (int trial = 0; trial < 4; ++trial) {
    RowSystem s = trial % 2 == 0 ? exact_test::pointMassChain(30, rng) : exact_test::rigidChain(15, rng);
    if (trial >= 2) {
      for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-4);
    }
    const std::vector<SolverBody> v_star = s.bodies;
    const DenseLcp lcp = assembleDenseLcp(s.rows, s.bodies);
    const Eigen::VectorXd ldlt = lcp.A.ldlt().solve(-lcp.b);

    RowSystem exact = s;
    ASSERT_TRUE(solveLcpExact(exact.rows, exact.bodies).converged);

    DirectSolver solver;
    const DirectSolveStats st = solver.solve(s.rows, s.bodies, coldOptions(5, 5));
    EXPECT_EQ(st.bilateral_rows, static_cast<int>(s.rows.size()));
    EXPECT_EQ(st.unilateral_rows, 0);
    EXPECT_EQ(st.outer_iterations, 1);  // nothing left to iterate on
    EXPECT_FALSE(st.regularized);
    const std::vector<double> direct = rowLambdas(s.rows);
    const std::vector<double> dense(ldlt.data(), ldlt.data() + ldlt.size());
    EXPECT_LE(lambdaDistance(direct, dense), 1e-9) << "trial " << trial;
    EXPECT_LE(lambdaDistance(direct, rowLambdas(exact.rows)), 1e-9) << "trial " << trial;
    EXPECT_LE(velocityMismatch(s, v_star), 1e-12);
    EXPECT_LE(st.residual, 1e-10);
  }
}

// A chain hanging from the world (bilateral) whose bodies touch the ground
// with friction and are driven by bounded motors. Block Gauss-Seidel
// decreases the natural-map residual from one outer iteration to the next
// and approaches the exact LCP solution.
TEST(DirectSolver, ResidualDecreasesWithOuterIterations) {
  std::mt19937 rng(42);
  RowSystem s = exact_test::rigidChain(8, rng);
  for (int b = 1; b <= 8; ++b) {
    s.bodies[static_cast<std::size_t>(b)].v += Vec3(0.4, -1.0, 0);
    s.addContact(b, exact_test::randomVec(rng, 0.4), Vec3(0, 1, 0), 0.5, 0.01);
  }
  for (int b = 1; b < 8; b += 2) {
    ConstraintRow& m = s.addPointRow(b, b + 1, exact_test::randomVec(rng), exact_test::randomVec(rng), Vec3::UnitZ());
    m.lo = -0.2;
    m.hi = 0.2;
    m.rhs = 1.0;
  }
  for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-4);
  const RowSystem exact_before = s;
  RowSystem exact = s;
  ASSERT_TRUE(solveLcpExact(exact.rows, exact.bodies).converged);

  DirectSolver solver;
  const int outer = 40;
  const DirectSolveStats st = solver.solve(s.rows, s.bodies, coldOptions(outer, 4));
  ASSERT_EQ(st.residual_history.size(), static_cast<std::size_t>(outer));
  EXPECT_GT(st.bilateral_rows, 0);
  EXPECT_GT(st.unilateral_rows, 0);
  // Not every single iteration need decrease (the natural map is not the
  // objective block Gauss-Seidel descends), so compare checkpoints.
  const std::vector<double>& h = st.residual_history;
  for (std::size_t k : {std::size_t(0), std::size_t(4), std::size_t(9), std::size_t(19)}) {
    const std::size_t next = 2 * k + 1;
    EXPECT_LT(h[next], h[k]) << "iteration " << k + 1 << " -> " << next + 1;
  }
  EXPECT_LT(h.back(), 1e-3 * h.front());
  // And the impulses approach the exact LCP solution.
  RowSystem few = exact_before;
  DirectSolver().solve(few.rows, few.bodies, coldOptions(5, 4));
  const double far = lambdaDistance(rowLambdas(few.rows), rowLambdas(exact.rows));
  const double near = lambdaDistance(rowLambdas(s.rows), rowLambdas(exact.rows));
  EXPECT_LT(near, 0.1 * far);
  EXPECT_LT(near, 1e-2);
  std::printf("[ info ] residual after 1, 5, 10, 20, 40 outer iterations: %.2e %.2e %.2e %.2e %.2e; "
              "distance to exact after 5, 40: %.2e %.2e\n",
              h[0], h[4], h[9], h[19], h[39], far, near);
}

// The symbolic analysis depends only on which bilateral rows share which
// bodies: new values reuse it, a new pattern triggers a new one.
TEST(DirectSolver, ReusesSymbolicAnalysisWhileStructureIsUnchanged) {
  std::mt19937 rng(43);
  RowSystem s = exact_test::rigidChain(10, rng);
  s.addContact(3, exact_test::randomVec(rng, 0.3), Vec3(0, 1, 0), 0.5, 0.0);
  DirectSolver solver;
  const DirectSolverOptions opt = coldOptions(3, 3);

  RowSystem a = s;
  const DirectSolveStats first = solver.solve(a.rows, a.bodies, opt);
  EXPECT_TRUE(first.analysed);
  EXPECT_EQ(solver.analysisCount(), 1);

  // Same structure, different numbers: new velocities, rhs and Jacobians
  // (the bodies move between steps), a different contact state.
  RowSystem b = s;
  for (SolverBody& body : b.bodies) body.v += exact_test::randomVec(rng);
  b.bodies[0] = SolverBody{};
  for (ConstraintRow& r : b.rows) {
    r.rhs += uniform(rng, -0.1, 0.1);
    r.j_ang_b *= 1.1;
    r.m_ang_b *= 1.1;
  }
  const DirectSolveStats second = solver.solve(b.rows, b.bodies, opt);
  EXPECT_FALSE(second.analysed);
  EXPECT_EQ(second.analysis_count, 1);
  EXPECT_EQ(solver.analysisCount(), 1);
  EXPECT_EQ(second.structure_hash, first.structure_hash);
  // Unilateral rows do not enter A_BB: adding a contact keeps the analysis.
  RowSystem c = s;
  c.addContact(7, exact_test::randomVec(rng, 0.3), Vec3(0, 1, 0), 0.5, 0.0);
  EXPECT_FALSE(solver.solve(c.rows, c.bodies, opt).analysed);
  EXPECT_EQ(solver.analysisCount(), 1);

  // A new joint between bodies 2 and 9 closes a loop: new pattern.
  RowSystem d = s;
  d.addBall(2, 9, exact_test::randomVec(rng, 0.5), exact_test::randomVec(rng, 0.5), 0.0, rng);
  for (ConstraintRow& r : d.rows) d.setCfm(r, 1e-6);
  const DirectSolveStats fourth = solver.solve(d.rows, d.bodies, opt);
  EXPECT_TRUE(fourth.analysed);
  EXPECT_EQ(solver.analysisCount(), 2);
  EXPECT_NE(fourth.structure_hash, first.structure_hash);
  // And back: the old pattern is analysed again (one analysis is kept).
  RowSystem e = s;
  EXPECT_TRUE(solver.solve(e.rows, e.bodies, opt).analysed);
  EXPECT_EQ(solver.analysisCount(), 3);

  // Every solve above was still exact on its bilateral rows.
  for (const RowSystem* sys : {&a, &b, &c, &e}) {
    for (const ConstraintRow& r : sys->rows) {
      if (r.lo == -kInf && r.hi == kInf && r.normal_row < 0) {
        EXPECT_NEAR(rowJv(r, sys->bodies) - r.rhs + r.cfm * r.lambda, 0.0, 1e-9);
      }
    }
  }
}

// A closed loop of joints with cfm = 0 (two ball joints between the same
// bodies) makes A_BB singular. The solver regularizes, says so, returns
// finite impulses, and its outer iterations (proximal steps on the true
// residual) still drive the consistent constraints to w = 0.
TEST(DirectSolver, RedundantBilateralRowsWithoutCfmAreRegularized) {
  std::mt19937 rng(44);
  RowSystem s = exact_test::rigidChain(4, rng);
  for (int k = 0; k < 3; ++k) s.rows.push_back(s.rows[static_cast<std::size_t>(6 + k)]);  // joint 3 twice
  const std::vector<SolverBody> v_star = s.bodies;
  DirectSolver solver;
  const DirectSolveStats st = solver.solve(s.rows, s.bodies, coldOptions(4, 1));
  EXPECT_TRUE(st.regularized);
  // The chain is a tree, but a singular A_BB is CHOLMOD's to regularise
  // (solver/direct_solver.cpp): the tree factor's attempt and CHOLMOD's
  // shifted factorization.
  EXPECT_FALSE(st.tree_factor);
  EXPECT_GT(st.regularization, 0);
  EXPECT_FALSE(st.factorization_failed);
  EXPECT_EQ(st.factorizations, 2);
  for (const ConstraintRow& r : s.rows) ASSERT_TRUE(std::isfinite(r.lambda));
  EXPECT_LE(velocityMismatch(s, v_star), 1e-9);
  EXPECT_LE(st.residual, 1e-8);
  // The pair shares the impulse evenly (regularization picks the
  // minimum-norm split of a consistent redundant pair).
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(s.rows[static_cast<std::size_t>(6 + k)].lambda, s.rows[static_cast<std::size_t>(12 + k)].lambda, 1e-6);
  }
}

// With cfm > 0 the same redundancy is positive definite: no
// regularization, and the answer is the exact solver's.
TEST(DirectSolver, RedundantRowsWithCfmStayFiniteAndExact) {
  std::mt19937 rng(45);
  RowSystem s = exact_test::rigidChain(4, rng);
  for (int k = 0; k < 3; ++k) s.rows.push_back(s.rows[static_cast<std::size_t>(6 + k)]);
  for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-5);
  RowSystem exact = s;
  solveLcpExact(exact.rows, exact.bodies);
  DirectSolver solver;
  const DirectSolveStats st = solver.solve(s.rows, s.bodies, coldOptions(1, 0));
  EXPECT_FALSE(st.regularized);
  for (const ConstraintRow& r : s.rows) ASSERT_TRUE(std::isfinite(r.lambda));
  // cond(A + C) ~ max eig / 1e-5 ~ 1e6 here, so 1e-9 relative still holds
  // with room (round-off ~ 1e-16 * 1e6).
  EXPECT_LE(lambdaDistance(rowLambdas(s.rows), rowLambdas(exact.rows)), 1e-9);
}

// Warm starting: whether the velocities on entry already contain the
// warm-start impulse or not, the result is v = v* + M^-1 J^T lambda; and a
// warm start from the converged answer stays there.
TEST(DirectSolver, WarmStartConventionsAgree) {
  std::mt19937 rng(46);
  RowSystem s = exact_test::rigidChain(5, rng);
  for (int b = 1; b <= 5; ++b) s.addContact(b, exact_test::randomVec(rng, 0.4), Vec3(0, 1, 0), 0.5, 0.02);
  for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-4);
  for (ConstraintRow& r : s.rows) r.lambda = uniform(rng, 0, 0.5);
  const std::vector<SolverBody> v_star = s.bodies;

  RowSystem applied = s;
  for (const ConstraintRow& r : applied.rows) applyRowImpulse(r, r.lambda, applied.bodies);
  DirectSolverOptions opt;
  opt.outer_iterations = 6;
  opt.inner_pgs_iterations = 6;
  DirectSolver solver;
  solver.solve(s.rows, s.bodies, opt);
  opt.velocities_include_lambda = true;
  solver.solve(applied.rows, applied.bodies, opt);
  EXPECT_LE(lambdaDistance(rowLambdas(s.rows), rowLambdas(applied.rows)), 1e-12);
  EXPECT_LE(velocityMismatch(s, v_star), 1e-12);
  EXPECT_LE(velocityMismatch(applied, v_star), 1e-12);

  // From the exact answer, with the velocities matching it, nothing moves.
  RowSystem exact = s;
  exact.bodies = v_star;
  solveLcpExact(exact.rows, exact.bodies);
  const std::vector<double> before = rowLambdas(exact.rows);
  const DirectSolveStats st = solver.solve(exact.rows, exact.bodies, opt);
  EXPECT_LE(lambdaDistance(rowLambdas(exact.rows), before), 1e-10);
  EXPECT_LE(st.residual, 1e-10);
}

}  // namespace
}  // namespace cairn
