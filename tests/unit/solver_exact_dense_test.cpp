// A = J M^-1 J^T and b = J v - rhs assembled from the rows, dense and
// sparse, against the explicit matrix product.
#include "solver/dense_system.hpp"
#include "solver_exact_fixtures.hpp"

#include <gtest/gtest.h>

namespace cairn {
namespace {

using exact_test::RowSystem;

// A chain of rigid bodies with ball joints, contacts with friction, a row
// whose two sides name the same body, a row to a static (zero-mass, non-
// world) body and rows listing their bodies in both orders.
RowSystem mixedSystem(std::mt19937& rng) {
  RowSystem s = exact_test::rigidChain(5, rng);
  const int fixed = s.addBody(0, Mat3::Zero(), exact_test::randomVec(rng));  // kinematic: moves, zero M^-1
  s.addContact(2, exact_test::randomVec(rng, 0.5), Vec3(0.1, 1, 0), 0.6, 0.05);
  s.addContact(5, exact_test::randomVec(rng, 0.5), Vec3(0, 1, 0.2), 0.4, -0.02);
  s.addPointRow(3, 3, exact_test::randomVec(rng), exact_test::randomVec(rng), Vec3(0, 0, 1)).rhs = 0.1;
  s.addPointRow(fixed, 4, exact_test::randomVec(rng), exact_test::randomVec(rng), Vec3(1, 0, 0)).rhs = -0.1;
  s.addPointRow(4, 1, exact_test::randomVec(rng), exact_test::randomVec(rng), Vec3(0, 1, 0));
  for (std::size_t i = 0; i < s.rows.size(); i += 3) s.setCfm(s.rows[i], 1e-3 * static_cast<Real>(i + 1));
  return s;
}

// Entries of A are sums of a few products of O(1) numbers, so the row
// assembly and the explicit triple product differ by round-off only:
// 1e-12 of the largest entry leaves a 1e3 margin over double epsilon times
// the number of terms.
TEST(DenseSystem, DenseAMatchesExplicitJacobianProduct) {
  std::mt19937 rng(11);
  const RowSystem s = mixedSystem(rng);
  const Eigen::MatrixXd j = s.jacobian();
  const Eigen::MatrixXd expect = j * s.inverseMass() * j.transpose();
  const Eigen::MatrixXd a = assembleDenseA(s.rows);
  const Real scale = expect.cwiseAbs().maxCoeff();
  EXPECT_LE((a - expect).cwiseAbs().maxCoeff(), 1e-12 * scale);
  EXPECT_EQ(a, a.transpose());  // exactly symmetric

  const Eigen::MatrixXd with_cfm = assembleDenseA(s.rows, CfmOnDiagonal::Include);
  EXPECT_LE((with_cfm - expect - Eigen::MatrixXd(s.cfmVector().asDiagonal())).cwiseAbs().maxCoeff(), 1e-12 * scale);

  Eigen::VectorXd rhs(static_cast<Eigen::Index>(s.rows.size()));
  for (std::size_t i = 0; i < s.rows.size(); ++i) rhs(static_cast<Eigen::Index>(i)) = s.rows[i].rhs;
  const Eigen::VectorXd b_expect = j * s.velocityVector() - rhs;
  EXPECT_LE((assembleB(s.rows, s.bodies) - b_expect).cwiseAbs().maxCoeff(), 1e-12);
}

// The sparse assembly visits rows body by body, the dense one pair by pair:
// same products, different summation order, so they agree to round-off.
TEST(DenseSystem, SparseAssemblyEqualsDenseAssembly) {
  std::mt19937 rng(12);
  const RowSystem s = mixedSystem(rng);
  for (CfmOnDiagonal cfm : {CfmOnDiagonal::Exclude, CfmOnDiagonal::Include}) {
    const Eigen::MatrixXd dense = assembleDenseA(s.rows, cfm);
    const Eigen::SparseMatrix<double> sparse = assembleSparseA(s.rows, cfm);
    EXPECT_TRUE(sparse.isCompressed());
    EXPECT_LE((Eigen::MatrixXd(sparse) - dense).cwiseAbs().maxCoeff(), 1e-13 * dense.cwiseAbs().maxCoeff());
    EXPECT_EQ((sparse - Eigen::SparseMatrix<double>(sparse.transpose())).norm(), 0.0);  // exactly symmetric

    // A principal submatrix in a shuffled order.
    const std::vector<int> subset{7, 2, 0, 11, 5, 16, 3};
    const Eigen::SparseMatrix<double> sub = assembleSparseA(s.rows, subset, cfm);
    ASSERT_EQ(sub.rows(), static_cast<Eigen::Index>(subset.size()));
    const Eigen::MatrixXd expect = dense(subset, subset);
    EXPECT_LE((Eigen::MatrixXd(sub) - expect).cwiseAbs().maxCoeff(), 1e-13 * dense.cwiseAbs().maxCoeff());
  }
}

// The direct solver's one-triangle assembly is the lower triangle of the
// full one, bit for bit (the same terms summed in the same order), with the
// same pattern (every diagonal stored), whatever rows it is given and in
// whichever order; and it reuses its scratch across calls.
TEST(DenseSystem, LowerAssemblyIsTheFullAssemblysLowerTriangleExactly) {
  std::mt19937 rng(12);
  const RowSystem s = mixedSystem(rng);
  SparseAssembly scratch;
  Eigen::SparseMatrix<double> lower;
  std::vector<int> all(s.rows.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  for (CfmOnDiagonal cfm : {CfmOnDiagonal::Exclude, CfmOnDiagonal::Include})
    for (const std::vector<int>& subset : {all, std::vector<int>{7, 2, 0, 11, 5, 16, 3}}) {
      const Eigen::SparseMatrix<double> full = assembleSparseA(s.rows, subset, cfm);
      assembleSparseLower(s.rows, subset, cfm, scratch, lower);
      EXPECT_TRUE(lower.isCompressed());
      const Eigen::SparseMatrix<double> expect = full.triangularView<Eigen::Lower>();
      ASSERT_EQ(lower.nonZeros(), expect.nonZeros());
      for (Eigen::Index k = 0; k < expect.nonZeros(); ++k) {
        EXPECT_EQ(lower.innerIndexPtr()[k], expect.innerIndexPtr()[k]);
        EXPECT_EQ(lower.valuePtr()[k], expect.valuePtr()[k]);
      }
      for (Eigen::Index c = 0; c <= expect.cols(); ++c) EXPECT_EQ(lower.outerIndexPtr()[c], expect.outerIndexPtr()[c]);
    }
}

// Rows that share only the world or a zero-mass body do not couple: the
// sparse pattern holds their diagonals only, and a row naming the same body
// on both sides gets (J_a + J_b) M^-1 (J_a + J_b)^T.
TEST(DenseSystem, OnlyMovingSharedBodiesCouple) {
  RowSystem s;
  const int p = s.addBody(1.0, Mat3::Identity());
  const int q = s.addBody(0.5, Mat3::Identity());
  const int still = s.addBody(0, Mat3::Zero());
  s.addRow(0, p, Vec3::Zero(), Vec3::Zero(), Vec3::UnitX(), Vec3::Zero());
  s.addRow(0, q, Vec3::Zero(), Vec3::Zero(), Vec3::UnitX(), Vec3::Zero());
  s.addRow(still, p, Vec3::UnitY(), Vec3::Zero(), Vec3::UnitZ(), Vec3::UnitY());
  s.addRow(q, still, Vec3::UnitZ(), Vec3::Zero(), Vec3::UnitY(), Vec3::Zero());
  const Eigen::SparseMatrix<double> a = assembleSparseA(s.rows);
  // Rows 0 and 2 share p; rows 1 and 3 share q; nothing else.
  EXPECT_EQ(a.nonZeros(), 4 + 4);
  EXPECT_EQ(a.coeff(0, 1), 0.0);
  EXPECT_EQ(a.coeff(2, 3), 0.0);
  EXPECT_DOUBLE_EQ(a.coeff(0, 2), 0.0);  // x . z = 0 but structurally present (shares p)
  EXPECT_DOUBLE_EQ(a.coeff(2, 2), 2.0);  // 1/m |z|^2 + |y|^2 I^-1

  RowSystem t;
  const int r = t.addBody(0.5, 2.0 * Mat3::Identity());
  t.addRow(r, r, Vec3::UnitX(), Vec3::UnitZ(), Vec3::UnitX(), Vec3::Zero());
  // (2 e_x, e_z) M^-1 (2 e_x, e_z)^T = 0.5 * 4 + 2 * 1 = 4.
  EXPECT_DOUBLE_EQ(assembleDenseA(t.rows)(0, 0), 4.0);
  EXPECT_DOUBLE_EQ(Eigen::MatrixXd(assembleSparseA(t.rows))(0, 0), 4.0);
}

}  // namespace
}  // namespace cairn
