// The tree factor (solver/tree_factor.hpp): the linear-time block Cholesky
// of A_BB + C_B for joints whose bodies form a forest, checked against
// Eigen's dense LLT of the same matrix, and its refusal of the structures
// it cannot factor without fill (closed loops).
#include "solver/dense_system.hpp"
#include "solver/direct_solver.hpp"
#include "solver/tree_factor.hpp"
#include "solver_exact_fixtures.hpp"

#include <gtest/gtest.h>

#include <numeric>

namespace cairn {
namespace {

using exact_test::RowSystem;
using exact_test::randomSpd;
using exact_test::randomVec;
using exact_test::uniform;

int addRigidBody(RowSystem& s, std::mt19937& rng) {
  return s.addBody(1 / uniform(rng, 0.3, 3.0), randomSpd(rng, 0.05, 0.5).inverse(), randomVec(rng), randomVec(rng));
}

// A hinge-like group of `rows` rows between a and b: point rows along the
// axes, then angular rows about random directions.
void addJoint(RowSystem& s, int a, int b, int rows, std::mt19937& rng) {
  const Vec3 ra = randomVec(rng, 0.5), rb = randomVec(rng, 0.5);
  for (int k = 0; k < rows; ++k) {
    if (k < 3) {
      s.addPointRow(a, b, ra, rb, Vec3::Unit(k));
    } else {
      const Vec3 u = randomVec(rng).normalized();
      s.addRow(a, b, Vec3::Zero(), -u, Vec3::Zero(), u);
    }
  }
}

// A random tree of joints over n bodies: body k hangs from a random
// earlier body (the world for some), with 1 to 6 rows; the sides are
// listed either way round, every fifth body carries a second group of two
// rows to the world (its own joint then has at most four, so no body is
// held by more rows than it has freedoms and A stays nonsingular), and
// one row names its body on both sides.
RowSystem randomTree(int n, std::mt19937& rng) {
  RowSystem s;
  for (int k = 1; k <= n; ++k) {
    const int id = addRigidBody(s, rng);
    const int parent = k == 1 || uniform(rng, 0, 1) < 0.15 ? 0 : 1 + static_cast<int>(uniform(rng, 0, k - 1 - 1e-9));
    const int rows = 1 + static_cast<int>(uniform(rng, 0, (k % 5 == 0 ? 4 : 6) - 1e-9));
    if (uniform(rng, 0, 1) < 0.5) addJoint(s, parent, id, rows, rng);
    else addJoint(s, id, parent, rows, rng);
    if (k % 5 == 0) addJoint(s, 0, id, 2, rng);  // a second group hanging off the body
  }
  // Both sides on one body: J_a + J_b is its row for that body.
  s.addRow(2, 2, randomVec(rng), randomVec(rng), randomVec(rng), randomVec(rng));
  for (ConstraintRow& r : s.rows) r.rhs = uniform(rng, -1, 1);
  return s;
}

std::vector<int> everyRow(const RowSystem& s) {
  std::vector<int> all(s.rows.size());
  std::iota(all.begin(), all.end(), 0);
  return all;
}

// Solves (A + C + shift I) x = b with the tree factor and with a dense LLT
// of the same matrix. The rows are random but well conditioned (masses and
// inertias within a factor 10, levers under 1), cond < 1e5 here, so 1e-9
// relative is round-off with a wide margin.
void expectMatchesDense(const RowSystem& s, double shift, const char* what) {
  const std::vector<int> all = everyRow(s);
  TreeFactor tree;
  ASSERT_TRUE(tree.analyse(s.rows, all)) << what;
  ASSERT_TRUE(tree.factorize(s.rows, all, shift)) << what;
  EXPECT_GT(tree.pivotRatio(), 0) << what;
  const Eigen::MatrixXd a = assembleDenseA(s.rows, CfmOnDiagonal::Include) +
                            shift * Eigen::MatrixXd::Identity(static_cast<Eigen::Index>(all.size()), static_cast<Eigen::Index>(all.size()));
  Eigen::VectorXd b(static_cast<Eigen::Index>(all.size()));
  for (Eigen::Index i = 0; i < b.size(); ++i) b(i) = std::sin(1.7 * static_cast<double>(i) + 0.3);
  const Eigen::VectorXd dense = a.llt().solve(b);
  Eigen::VectorXd x = b;
  tree.solveInPlace(std::span<double>(x.data(), static_cast<std::size_t>(x.size())));
  EXPECT_LE((x - dense).norm(), 1e-9 * dense.norm()) << what;
  // And the factor is a factor of A: the residual of the solve is round-off.
  EXPECT_LE((a * x - b).norm(), 1e-9 * b.norm()) << what;
}

TEST(TreeFactor, ChainSolveMatchesDenseCholesky) {
  std::mt19937 rng(61);
  expectMatchesDense(exact_test::rigidChain(40, rng), 0.0, "rigid chain");
  expectMatchesDense(exact_test::pointMassChain(60, rng), 0.0, "point-mass chain");
}

TEST(TreeFactor, RandomTreesOfMixedJointsMatchDenseCholesky) {
  std::mt19937 rng(62);
  for (int trial = 0; trial < 6; ++trial) {
    RowSystem s = randomTree(30, rng);
    if (trial % 2 == 1)
      for (ConstraintRow& r : s.rows) s.setCfm(r, 1e-4);
    expectMatchesDense(s, trial == 4 ? 1e-6 : 0.0, "random tree");
  }
}

// Rows that move no body (both sides on the world) with cfm > 0: a
// diagonal group coupled to nothing.
TEST(TreeFactor, RowsMovingNoBodyAreTheirOwnGroup) {
  std::mt19937 rng(63);
  RowSystem s = exact_test::rigidChain(5, rng);
  ConstraintRow& r = s.addRow(0, 0, randomVec(rng), randomVec(rng), randomVec(rng), randomVec(rng));
  s.setCfm(r, 0.5);
  expectMatchesDense(s, 0.0, "inert row with cfm");
}

// A loop (a ball joint closing the chain back on an earlier body) would
// fill in: the tree factor refuses it, and the direct solver gives the
// same exact answer through CHOLMOD instead.
TEST(TreeFactor, ClosedLoopIsRefusedAndTheDirectSolverFallsBackToCholmod) {
  std::mt19937 rng(64);
  RowSystem chain = exact_test::rigidChain(8, rng);
  RowSystem loop = chain;
  loop.addBall(2, 7, randomVec(rng, 0.5), randomVec(rng, 0.5), 0.1, rng);
  for (ConstraintRow& row : loop.rows) loop.setCfm(row, 1e-6);
  TreeFactor tree;
  EXPECT_TRUE(tree.analyse(chain.rows, everyRow(chain)));
  EXPECT_FALSE(tree.analyse(loop.rows, everyRow(loop)));
  EXPECT_FALSE(tree.usable());

  DirectSolverOptions o;
  o.warm_start = false;
  DirectSolver solver;
  RowSystem a = chain;
  EXPECT_TRUE(solver.solve(a.rows, a.bodies, o).tree_factor);
  RowSystem b = loop;
  const DirectSolveStats st = solver.solve(b.rows, b.bodies, o);
  EXPECT_FALSE(st.tree_factor);
  EXPECT_TRUE(st.analysed);
  for (const ConstraintRow& row : b.rows) EXPECT_NEAR(rowJv(row, b.bodies) - row.rhs + row.cfm * row.lambda, 0.0, 1e-9);
}

// Many joints on one body make a clique whose elimination costs ~ d^3:
// past the limit the factor declines and CHOLMOD takes it.
TEST(TreeFactor, BodyWithManyJointsIsLeftToCholmod) {
  std::mt19937 rng(65);
  RowSystem star;
  const int hub = addRigidBody(star, rng);
  for (int k = 0; k < 60; ++k) addJoint(star, hub, addRigidBody(star, rng), 3, rng);
  TreeFactor tree;
  EXPECT_FALSE(tree.analyse(star.rows, everyRow(star)));
  RowSystem small;
  const int h2 = addRigidBody(small, rng);
  for (int k = 0; k < 6; ++k) addJoint(small, h2, addRigidBody(small, rng), 3, rng);
  expectMatchesDense(small, 0.0, "six joints on one body");
}

// A singular block (the same ball joint twice, cfm 0) fails the factor's
// positive-definiteness test as CHOLMOD's does.
TEST(TreeFactor, SingularBlockFailsThePivotTest) {
  std::mt19937 rng(66);
  RowSystem s = exact_test::rigidChain(4, rng);
  for (int k = 0; k < 3; ++k) s.rows.push_back(s.rows[static_cast<std::size_t>(6 + k)]);
  TreeFactor tree;
  ASSERT_TRUE(tree.analyse(s.rows, everyRow(s)));
  const bool ok = tree.factorize(s.rows, everyRow(s), 0.0);
  EXPECT_TRUE(!ok || tree.pivotRatio() < 1e-12);
}

}  // namespace
}  // namespace cairn
