// Dantzig's pivoting method on hand-built row systems: complementarity to
// round-off, agreement with LDLT and with brute-force enumeration, friction
// coupled to the final normal impulses, redundant rows.
#include "solver/dense_system.hpp"
#include "solver/lcp_exact.hpp"
#include "solver/lcp_residual.hpp"
#include "solver_exact_fixtures.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

namespace cairn {
namespace {

using exact_test::complementarityViolation;
using exact_test::RowSystem;
using exact_test::uniform;
using exact_test::velocityMismatch;

// Impulses and velocities here are O(1) and A is well conditioned (the
// chains are short), so the pivoting's final re-solve leaves round-off of
// order 1e-14; 1e-10 is the brief's bar with a wide margin.
constexpr Real kComplementarityTol = 1e-10;

// Bilateral rows only: the LCP is the linear system (A + C) lambda = -b.
TEST(ExactLcp, BilateralChainMatchesLdlt) {
  std::mt19937 rng(31);
  for (int trial = 0; trial < 3; ++trial) {
    RowSystem s = trial == 0 ? exact_test::pointMassChain(12, rng) : exact_test::rigidChain(6, rng);
    if (trial == 2) {
      for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-3);
    }
    const std::vector<SolverBody> v_star = s.bodies;
    const DenseLcp lcp = assembleDenseLcp(s.rows, s.bodies);
    const Eigen::VectorXd expect = lcp.A.ldlt().solve(-lcp.b);
    const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
    EXPECT_TRUE(res.converged);
    EXPECT_FALSE(res.regularized);
    // Relative 1e-12: cond(A) of these chains is below 1e3.
    EXPECT_LE((s.lambdaVector() - expect).norm(), 1e-12 * expect.norm()) << "trial " << trial;
    EXPECT_LE(velocityMismatch(s, v_star), 1e-12);
    EXPECT_LE(res.residual, kComplementarityTol);
  }
}

// A rigid chain with unilateral rows of every shape: contacts (lo = 0),
// motors (-m, m), limits that only pull (hi = 0), and a row whose box does
// not contain 0 (lo = 0.05: a minimum impulse). Some contacts separate and
// some push, so both sides of the complementarity are exercised.
TEST(ExactLcp, UnilateralRowsAreComplementary) {
  std::mt19937 rng(32);
  int pushing = 0, separating = 0, at_hi = 0, inside = 0;
  for (int trial = 0; trial < 10; ++trial) {
    RowSystem s = exact_test::rigidChain(5, rng);
    for (int b = 1; b <= 5; ++b) {
      s.addContact(b, exact_test::randomVec(rng, 0.4), Vec3(0.1, 1, -0.1), 0, uniform(rng, -0.2, 0.2));
    }
    ConstraintRow& motor = s.addPointRow(2, 3, exact_test::randomVec(rng), exact_test::randomVec(rng), Vec3::UnitX());
    motor.lo = -0.05;
    motor.hi = 0.05;
    motor.rhs = 2.0;  // asks for more than the motor can give
    ConstraintRow& limit = s.addPointRow(0, 4, Vec3::Zero(), exact_test::randomVec(rng), Vec3::UnitZ());
    limit.lo = -kInf;
    limit.hi = 0;
    limit.rhs = uniform(rng, -0.5, 0.5);
    ConstraintRow& min_push = s.addPointRow(1, 5, exact_test::randomVec(rng), exact_test::randomVec(rng), Vec3::UnitY());
    min_push.lo = 0.05;
    min_push.hi = 1.0;
    const std::vector<SolverBody> v_star = s.bodies;

    const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
    ASSERT_TRUE(res.converged) << "trial " << trial;
    EXPECT_LE(complementarityViolation(s, v_star), kComplementarityTol) << "trial " << trial;
    EXPECT_LE(res.residual, kComplementarityTol);
    EXPECT_LE(velocityMismatch(s, v_star), 1e-12);
    for (const ConstraintRow& r : s.rows) {
      if (r.kind != RowKind::ContactNormal) continue;
      (r.lambda > 0 ? pushing : separating)++;
    }
    const ConstraintRow& m = s.rows[s.rows.size() - 3];
    (std::abs(std::abs(m.lambda) - 0.05) < 1e-14 ? at_hi : inside)++;
  }
  EXPECT_GT(pushing, 5);
  EXPECT_GT(separating, 5);
  EXPECT_GT(at_hi, 0);  // the motor saturates at least once
}

// Random positive definite LCPs small enough to enumerate: every row is at
// lo, at hi or free (3^n guesses), each guess is one linear solve, and for
// a P-matrix exactly one guess satisfies the conditions. Pivoting must find
// that one.
TEST(ExactLcp, MatchesBruteForceEnumeration) {
  std::mt19937 rng(33);
  constexpr int n = 6;
  for (int trial = 0; trial < 25; ++trial) {
    Eigen::MatrixXd g(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) g(i, j) = uniform(rng, -1, 1);
    const Eigen::MatrixXd a = g * g.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd b(n), lo(n), hi(n);
    for (int i = 0; i < n; ++i) {
      b(i) = uniform(rng, -2, 2);
      switch ((trial + i) % 5) {
        case 0: lo(i) = -kInf; hi(i) = kInf; break;
        case 1: lo(i) = 0; hi(i) = kInf; break;
        case 2: lo(i) = -uniform(rng, 0, 1); hi(i) = uniform(rng, 0, 1); break;
        case 3: lo(i) = -kInf; hi(i) = 0; break;
        default: lo(i) = uniform(rng, 0.1, 0.3); hi(i) = uniform(rng, 0.5, 1); break;
      }
    }
    // Enumerate.
    Eigen::VectorXd found;
    int solutions = 0;
    for (int code = 0; code < 729; ++code) {
      int c = code;
      std::vector<int> free_rows;
      Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
      bool ok = true;
      for (int i = 0; i < n; ++i, c /= 3) {
        const int s = c % 3;
        if (s == 0) {
          free_rows.push_back(i);
        } else {
          const Real v = s == 1 ? lo(i) : hi(i);
          if (!std::isfinite(v)) ok = false;
          x(i) = v;
        }
      }
      if (!ok) continue;
      if (!free_rows.empty()) {
        const Eigen::VectorXd w_fixed = b + a * x;  // free rows are still 0 in x
        const Eigen::VectorXd rhs = -w_fixed(free_rows);
        const Eigen::MatrixXd a_ff = a(free_rows, free_rows);
        const Eigen::VectorXd x_free = a_ff.ldlt().solve(rhs);
        x(free_rows) = x_free;
      }
      if (complementarityViolation(a, b, x, lo, hi, {}, {}) < 1e-9) {
        ++solutions;
        found = x;
      }
    }
    ASSERT_GE(solutions, 1) << "trial " << trial;
    ExactLcpResult res;
    const Eigen::VectorXd x = solveLcpExactDense(a, b, lo, hi, {}, {}, &res);
    EXPECT_TRUE(res.converged);
    EXPECT_LE((x - found).norm(), 1e-10 * std::max(1.0, found.norm())) << "trial " << trial;
    EXPECT_LE(complementarityViolation(a, b, x, lo, hi, {}, {}), kComplementarityTol);
  }
}

// ExactLcpSolver keeps its workspace from solve to solve (the step's exact
// islands allocate nothing once warm). Whatever it solved before, its
// answer is a fresh solver's, bit for bit: problems of 12, 5 and 12 rows
// (bounded, unbounded, friction coupled to a normal, a singular pair that
// forces the regularized restart) solved in turn by one solver and each by
// a new one, the answers and every figure of the results compared with ==.
TEST(ExactLcp, ReusedSolverGivesAFreshSolversAnswerBitForBit) {
  std::mt19937 rng(36);
  struct Dense {
    Eigen::MatrixXd a;
    Eigen::VectorXd b, lo, hi;
    std::vector<int> findex;
  };
  const auto make = [&](int n, bool singular) {
    Dense d;
    Eigen::MatrixXd g(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) g(i, j) = uniform(rng, -1, 1);
    if (singular) g.row(n - 1) = g.row(0);  // two equal rows: A singular without cfm
    d.a = g * g.transpose();
    d.b.resize(n);
    d.lo.resize(n);
    d.hi.resize(n);
    d.findex.assign(static_cast<std::size_t>(n), -1);
    for (int i = 0; i < n; ++i) {
      d.b(i) = uniform(rng, -2, 2);
      d.lo(i) = i % 3 == 0 ? -kInf : 0;
      d.hi(i) = kInf;
      if (i % 4 == 3) {  // friction on the row before: hi carries mu
        d.findex[static_cast<std::size_t>(i)] = i - 1;
        d.hi(i) = 0.5;
      }
    }
    if (singular) {  // the copy unbounded like row 0: both are clamped, the second dependent
      d.findex[static_cast<std::size_t>(n - 1)] = -1;
      d.lo(n - 1) = -kInf;
      d.hi(n - 1) = kInf;
    }
    return d;
  };
  const Dense problems[] = {make(12, false), make(5, true), make(12, true), make(12, false)};
  ExactLcpSolver reused;
  int restarts = 0;
  for (const Dense& d : problems) {
    ExactLcpResult again, fresh;
    const Eigen::VectorXd x_again = reused.solveDense(d.a, d.b, d.lo, d.hi, d.findex, {}, &again);
    ExactLcpSolver other;
    const Eigen::VectorXd x_fresh = other.solveDense(d.a, d.b, d.lo, d.hi, d.findex, {}, &fresh);
    ASSERT_EQ(x_again.size(), x_fresh.size());
    for (Eigen::Index i = 0; i < x_again.size(); ++i) EXPECT_EQ(x_again(i), x_fresh(i)) << i;
    EXPECT_EQ(again.converged, fresh.converged);
    EXPECT_EQ(again.pivots, fresh.pivots);
    EXPECT_EQ(again.residual, fresh.residual);
    EXPECT_EQ(again.regularized, fresh.regularized);
    EXPECT_EQ(again.friction_iterations, fresh.friction_iterations);
    restarts += fresh.regularized ? 1 : 0;
  }
  EXPECT_GT(restarts, 0);  // the restart's storage was exercised too
}

// Bodies resting on the ground at three points each, sliding sideways:
// some friction rows stick, some slide at mu lambda_n. The bounds must hold
// for the final normal impulses, which ODE's single pass does not promise
// (its bounds come from the normals before any friction row was placed);
// the active-set step and the fixed-point passes make them exact. cfm > 0
// keeps the 9 contact rows per 6-DOF body nonsingular, as ODE's global CFM
// does.
TEST(ExactLcp, FrictionHoldsForTheFinalNormalImpulses) {
  std::mt19937 rng(34);
  int sliding = 0, sticking = 0;
  Real worst_ode = 0;
  for (int trial = 0; trial < 6; ++trial) {
    RowSystem s;
    for (int k = 0; k < 3; ++k) {
      const int b = s.addBody(1 / uniform(rng, 0.5, 2), exact_test::randomSpd(rng, 0.1, 0.5).inverse(),
                              Vec3(uniform(rng, -1, 1), -1.0, uniform(rng, -1, 1)), exact_test::randomVec(rng, 0.5));
      for (int c = 0; c < 3; ++c) {
        const Vec3 r(uniform(rng, -0.5, 0.5), -0.3, uniform(rng, -0.5, 0.5));
        s.addContact(b, r, Vec3(uniform(rng, -0.1, 0.1), 1, uniform(rng, -0.1, 0.1)), uniform(rng, 0.2, 0.8),
                     uniform(rng, 0, 0.05));
      }
    }
    for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-3);
    const std::vector<SolverBody> v_star = s.bodies;

    RowSystem ode = s;
    ExactLcpOptions ode_only;
    ode_only.max_friction_iterations = 1;
    ode_only.polish_active_set = false;
    const ExactLcpResult ode_res = solveLcpExact(ode.rows, ode.bodies, ode_only);
    EXPECT_FALSE(ode_res.converged);
    worst_ode = std::max(worst_ode, complementarityViolation(ode, v_star));

    const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
    ASSERT_TRUE(res.converged) << "trial " << trial;
    EXPECT_LE(complementarityViolation(s, v_star), kComplementarityTol) << "trial " << trial;
    EXPECT_LE(res.residual, kComplementarityTol);
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
      const ConstraintRow& r = s.rows[i];
      if (r.normal_row < 0) continue;
      const Real bound = r.mu * s.rows[static_cast<std::size_t>(r.normal_row)].lambda;
      (std::abs(std::abs(r.lambda) - bound) < 1e-10 ? sliding : sticking)++;
    }
  }
  EXPECT_GT(sliding, 3);
  EXPECT_GT(sticking, 3);
  EXPECT_GT(worst_ode, 1e-3);  // the coupling is not a round-off matter
}

// solveLcpExactDense follows ODE's findex convention (hi carries mu) and
// agrees with the row interface on the same problem.
TEST(ExactLcp, DenseInterfaceUsesOdeFindexConvention) {
  std::mt19937 rng(35);
  RowSystem s = exact_test::rigidChain(2, rng);
  for (int b = 1; b <= 2; ++b) {
    s.bodies[static_cast<std::size_t>(b)].v += Vec3(0.5, -1, 0);
    s.addContact(b, exact_test::randomVec(rng, 0.3), Vec3(0, 1, 0), 0.3, 0);
  }
  const DenseLcp lcp = assembleDenseLcp(s.rows, s.bodies);
  Eigen::VectorXd lo = lcp.lo, hi = lcp.hi;
  std::vector<int> findex(s.rows.size(), -1);
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    if (s.rows[i].normal_row < 0) continue;
    findex[i] = s.rows[i].normal_row;
    hi(static_cast<Eigen::Index>(i)) = s.rows[i].mu;
    lo(static_cast<Eigen::Index>(i)) = -123;  // ignored
  }
  ExactLcpResult dense_res;
  const Eigen::VectorXd x = solveLcpExactDense(lcp.A, lcp.b, lo, hi, findex, {}, &dense_res);
  const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
  EXPECT_TRUE(dense_res.converged);
  EXPECT_TRUE(res.converged);
  EXPECT_LE((x - s.lambdaVector()).norm(), 1e-12 * x.norm());
  EXPECT_LE(dense_res.residual, kComplementarityTol);
}

// The same row twice with cfm = 0 makes A singular. The solver detects the
// dependent pivot, restarts on A + r I and says so; the result is finite,
// the pair shares the impulse a single row would take, and the rows are
// satisfied up to r |lambda| (r = 1e-10 of the largest diagonal).
TEST(ExactLcp, RedundantRowsWithoutCfmAreRegularizedAndFinite) {
  std::mt19937 rng(36);
  RowSystem single = exact_test::rigidChain(3, rng);
  RowSystem twice = single;
  twice.rows.push_back(twice.rows[4]);   // a bilateral row, duplicated
  twice.rows.push_back(twice.rows[7]);
  twice.rows.back().lo = 0;              // and a contact-like copy of another
  twice.rows.back().hi = kInf;
  const std::vector<SolverBody> v_star = twice.bodies;

  const ExactLcpResult ref = solveLcpExact(single.rows, single.bodies);
  ASSERT_FALSE(ref.regularized);
  const ExactLcpResult res = solveLcpExact(twice.rows, twice.bodies);
  EXPECT_TRUE(res.regularized);
  EXPECT_GT(res.regularization, 0);
  EXPECT_TRUE(res.converged);
  for (const ConstraintRow& r : twice.rows) ASSERT_TRUE(std::isfinite(r.lambda));
  EXPECT_LE(velocityMismatch(twice, v_star), 1e-12);
  // Velocities agree with the non-redundant solve: the physics is the same.
  for (std::size_t b = 0; b < single.bodies.size(); ++b) {
    EXPECT_LE((twice.bodies[b].v - single.bodies[b].v).norm(), 1e-6) << "body " << b;
    EXPECT_LE((twice.bodies[b].w - single.bodies[b].w).norm(), 1e-6) << "body " << b;
  }
  EXPECT_NEAR(twice.rows[4].lambda + twice.rows[9].lambda, single.rows[4].lambda, 1e-6);
  EXPECT_LE(res.residual, 1e-8);
}

// With cfm > 0 the same redundancy is harmless: A + C is positive definite,
// no regularization is needed and the answer is exact.
TEST(ExactLcp, RedundantRowsWithCfmStayFiniteAndExact) {
  std::mt19937 rng(37);
  RowSystem s = exact_test::rigidChain(3, rng);
  for (int k = 0; k < 3; ++k) s.rows.push_back(s.rows[static_cast<std::size_t>(3 + k)]);  // a whole joint twice
  for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-5);
  const std::vector<SolverBody> v_star = s.bodies;
  const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
  EXPECT_TRUE(res.converged);
  EXPECT_FALSE(res.regularized);
  for (const ConstraintRow& r : s.rows) ASSERT_TRUE(std::isfinite(r.lambda));
  EXPECT_LE(complementarityViolation(s, v_star), kComplementarityTol);
  // The duplicate pair splits its impulse evenly (symmetric rows, equal cfm).
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(s.rows[static_cast<std::size_t>(3 + k)].lambda, s.rows[static_cast<std::size_t>(9 + k)].lambda, 1e-9);
  }
}

// A row that moves no body (both sides static) and has no cfm cannot change
// its own w: its impulse stays at clamp(0, lo, hi) and the rest is solved.
TEST(ExactLcp, InertRowIsPinnedAndHarmless) {
  std::mt19937 rng(38);
  RowSystem s = exact_test::rigidChain(2, rng);
  s.bodies[2].v += Vec3(0.5, -1, 0);
  s.addContact(2, exact_test::randomVec(rng, 0.3), Vec3(0, 1, 0), 0.4, 0.0);  // friction: the coupling loop runs
  const int still = s.addBody(0, Mat3::Zero());
  ConstraintRow& inert = s.addRow(0, still, Vec3::UnitX(), Vec3::Zero(), Vec3::UnitY(), Vec3::Zero());
  inert.rhs = 1.0;
  inert.lo = 0;
  const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
  EXPECT_TRUE(res.converged);
  EXPECT_FALSE(res.regularized);
  EXPECT_EQ(s.rows.back().lambda, 0.0);
  for (const ConstraintRow& r : s.rows) ASSERT_TRUE(std::isfinite(r.lambda));
  // Its own entry of the residual is its unsatisfiable w = -1; the others are solved.
  EXPECT_NEAR(res.residual, 1.0, 1e-12);
}

// The caller may hand over velocities that already contain the entry
// impulses (as PGS's warm start leaves them): same answer.
TEST(ExactLcp, VelocitiesIncludingLambdaGiveTheSameAnswer) {
  std::mt19937 rng(39);
  RowSystem s = exact_test::rigidChain(3, rng);
  s.addContact(2, exact_test::randomVec(rng, 0.3), Vec3(0, 1, 0), 0.5, 0.1);
  RowSystem warm = s;
  for (ConstraintRow& r : warm.rows) {
    r.lambda = uniform(rng, 0, 1);
    applyRowImpulse(r, r.lambda, warm.bodies);
  }
  ExactLcpOptions opt;
  opt.velocities_include_lambda = true;
  solveLcpExact(s.rows, s.bodies);
  solveLcpExact(warm.rows, warm.bodies, opt);
  EXPECT_LE((s.lambdaVector() - warm.lambdaVector()).norm(), 1e-12);
  EXPECT_LE((s.velocityVector() - warm.velocityVector()).norm(), 1e-12);
}

// A few hundred rows: a 40-body chain (120 joint rows) with 40 contacts
// (120 contact rows). Still exact; the timing bound is loose (the solve
// takes tens of milliseconds in Release) and only catches a blow-up in the
// pivot count or per-pivot cost.
TEST(ExactLcp, SolvesAFewHundredRows) {
  std::mt19937 rng(40);
  RowSystem s = exact_test::rigidChain(40, rng);
  for (int b = 1; b <= 40; ++b) {
    s.bodies[static_cast<std::size_t>(b)].v += Vec3(0.2, -0.5, 0);
    s.addContact(b, exact_test::randomVec(rng, 0.4), Vec3(0, 1, 0), 0.4, 0.01);
  }
  for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-4);
  const std::vector<SolverBody> v_star = s.bodies;
  const auto t0 = std::chrono::steady_clock::now();
  const ExactLcpResult res = solveLcpExact(s.rows, s.bodies);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(res.converged);
  // A long chain is less well conditioned (cond(A) ~ n^2 mass ratios), so
  // round-off grows: 1e-9 still means "exact".
  EXPECT_LE(complementarityViolation(s, v_star), 1e-9);
  EXPECT_LT(seconds, 5.0);
  std::printf("[ info ] %zu rows: %d pivots in %d passes, %.1f ms, residual %.2e\n", s.rows.size(), res.pivots,
              res.friction_iterations, 1e3 * seconds, res.residual);
}

}  // namespace
}  // namespace cairn
