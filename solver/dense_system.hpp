// The constraint rows as a matrix problem: A = J M^-1 J^T and b = J v* - rhs,
// assembled from the rows alone (docs/solvers-exact.md).
//
// Row i touches at most two bodies. Its Jacobian block for body k is
// (j_lin, j_ang) of the side(s) whose index is k, and the row caches the
// matching M^-1 J^T block (m_lin, m_ang). Hence
//
//     A_ij = sum over bodies k shared by rows i and j of  J_i(k) . (M^-1 J_j^T)(k)
//
// where a side counts only if its body index is not 0 (the world) and its
// M^-1 J^T block is not exactly zero (static, kinematic and sleeping bodies
// have zero blocks; see solver/solver_body.hpp). Since M is symmetric,
// J_i(k) M_k^-1 J_j(k)^T vanishes as soon as either row's block for k is
// zero, so skipping those sides changes no value and keeps rows that only
// share the ground from coupling in the sparse pattern. A row whose two
// sides name the same body sums both sides, which the formula above does
// automatically.
//
// The dense A is for small systems (the exact LCP solver, tests); the sparse
// A is built body by body, never through a dense matrix, and is what the
// direct solver factors with CHOLMOD.
#pragma once

#include "constraints/row.hpp"
#include "solver/solver_body.hpp"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <span>
#include <vector>

namespace cairn {

// Whether the assembled matrix carries the rows' cfm on its diagonal, i.e.
// A + diag(cfm), the matrix the mixed LCP is posed with.
enum class CfmOnDiagonal : bool { Exclude = false, Include = true };

// True when a row side moves its body: a non-world index with a non-zero
// M^-1 J^T block. Only such sides couple rows.
inline bool sideMovesBody(std::int32_t body, const Vec3& m_lin, const Vec3& m_ang) {
  return body != 0 && ((m_lin.array() != 0).any() || (m_ang.array() != 0).any());
}

// The body index a side couples through, or 0 when it couples through none.
inline std::int32_t couplingBodyA(const ConstraintRow& r) {
  return sideMovesBody(r.body_a, r.m_lin_a, r.m_ang_a) ? r.body_a : 0;
}
inline std::int32_t couplingBodyB(const ConstraintRow& r) {
  return sideMovesBody(r.body_b, r.m_lin_b, r.m_ang_b) ? r.body_b : 0;
}

// A_ij (without cfm) from two rows.
Real rowCoupling(const ConstraintRow& ri, const ConstraintRow& rj);

// A_ii (without cfm) given the row's coupling bodies ca = couplingBodyA(r)
// and cb = couplingBodyB(r): rowCoupling(r, r), summed in the same order.
inline Real rowSelfCoupling(const ConstraintRow& r, std::int32_t ca, std::int32_t cb) {
  const Real aa = ca != 0 ? r.j_lin_a.dot(r.m_lin_a) + r.j_ang_a.dot(r.m_ang_a) : Real(0);
  const Real bb = cb != 0 ? r.j_lin_b.dot(r.m_lin_b) + r.j_ang_b.dot(r.m_ang_b) : Real(0);
  if (ca == 0 || ca != cb) return aa + bb;
  const Real ab = r.j_lin_a.dot(r.m_lin_b) + r.j_ang_a.dot(r.m_ang_b);
  const Real ba = r.j_lin_b.dot(r.m_lin_a) + r.j_ang_b.dot(r.m_ang_a);
  return aa + ab + ba + bb;
}

// J_i v: the row's current relative velocity. Every side enters, including
// the world and kinematic bodies (whose velocity is what it is).
inline Real rowJv(const ConstraintRow& r, std::span<const SolverBody> bodies) {
  const SolverBody& a = bodies[static_cast<std::size_t>(r.body_a)];
  const SolverBody& b = bodies[static_cast<std::size_t>(r.body_b)];
  return r.j_lin_a.dot(a.v) + r.j_ang_a.dot(a.w) + r.j_lin_b.dot(b.v) + r.j_ang_b.dot(b.w);
}

// v += M^-1 J^T dlambda for the row's bodies. The world (index 0) is never
// moved, whatever the row says, so the velocities stay consistent with A.
inline void applyRowImpulse(const ConstraintRow& r, Real dlambda, std::span<SolverBody> bodies) {
  if (r.body_a != 0) {
    SolverBody& a = bodies[static_cast<std::size_t>(r.body_a)];
    a.v += r.m_lin_a * dlambda;
    a.w += r.m_ang_a * dlambda;
  }
  if (r.body_b != 0) {
    SolverBody& b = bodies[static_cast<std::size_t>(r.body_b)];
    b.v += r.m_lin_b * dlambda;
    b.w += r.m_ang_b * dlambda;
  }
}

// Dense A (n x n, exactly symmetric), optionally with cfm on the diagonal.
Eigen::MatrixXd assembleDenseA(std::span<const ConstraintRow> rows,
                               CfmOnDiagonal cfm = CfmOnDiagonal::Exclude);

// b_i = J_i v - rhs_i with v the given velocities (v* at a solver's entry).
Eigen::VectorXd assembleB(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies);

// Sparse A (n x n, compressed, both triangles, exactly symmetric). Every
// diagonal entry is stored, even when zero, so that a shift of the diagonal
// never changes the pattern. The pattern is a function of the rows'
// coupling bodies only (couplingBodyA/B), never of the values.
Eigen::SparseMatrix<double> assembleSparseA(std::span<const ConstraintRow> rows,
                                           CfmOnDiagonal cfm = CfmOnDiagonal::Exclude);

// The principal submatrix A[S, S] for the rows listed in `subset` (indices
// into `rows`, each at most once), in the order given. Same guarantees.
Eigen::SparseMatrix<double> assembleSparseA(std::span<const ConstraintRow> rows,
                                           std::span<const int> subset,
                                           CfmOnDiagonal cfm = CfmOnDiagonal::Exclude);

// Scratch arrays of assembleSparseLower, kept by its caller so that a
// steady scene assembles without allocating.
struct SparseAssembly {
  struct Entry {
    int row;
    double value;
  };
  std::vector<int> pos_of_row, bucket_start, bucket_fill, column_start, column_fill;
  std::vector<std::pair<int, bool>> sides;  // (row, side b?) bucketed by body
  std::vector<Entry> entries;
};

// The lower triangle of A[S, S] (+ cfm) written straight into `out`'s
// compressed arrays, for a solver that reads one triangle (CHOLMOD with
// Eigen::Lower): no triplet list, no row-major copy, no upper half, and no
// allocation once `scratch` has grown. Same pattern guarantees as below;
// assembleSparseA mirrors it.
void assembleSparseLower(std::span<const ConstraintRow> rows, std::span<const int> subset, CfmOnDiagonal cfm,
                         SparseAssembly& scratch, Eigen::SparseMatrix<double>& out);

// Everything the mixed LCP needs, dense:
//     w = A lambda + b,  lo <= lambda <= hi, complementarity (lcp_exact.hpp).
// A includes cfm. For a friction row (normal_row[i] >= 0) lo/hi hold the
// row's own fields, which the solvers replace by -+ mu[i] |lambda_normal|.
struct DenseLcp {
  Eigen::MatrixXd A;
  Eigen::VectorXd b, lo, hi, mu;
  std::vector<int> normal_row;
};
DenseLcp assembleDenseLcp(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies);
// The same into `lcp`, whose storage is kept where the size is (the step's
// exact solve, every substep).
void assembleDenseLcp(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies, DenseLcp& lcp);

}  // namespace cairn
