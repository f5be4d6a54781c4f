// Sparse block Cholesky of A_BB + C_B in linear time when the bilateral
// rows' bodies form a forest (docs/solvers-exact.md, "Tree factor").
//
// The rows are grouped by the pair of bodies they couple (a joint's rows
// are one group; a joint to the world, or a row coupling one body, is a
// group hanging off that body). Two groups are coupled in A = J M^-1 J^T
// exactly when they share a body. When no chain of groups closes a loop
// over the bodies, eliminating the groups leaves first, each after every
// other group at its child body, creates no fill: the groups a group
// still meets when it is eliminated all share its parent body and are
// coupled already. This is the ordering of Baraff's "Linear-Time Dynamics
// using Lagrange Multipliers" (SIGGRAPH 1996, section 5), applied to the
// joint-space matrix A rather than to the body-and-joint matrix he
// factors: for the ball and hinge joints of chains and ragdolls A's blocks
// are 3 x 3 to 6 x 6, against 6 x 6 body blocks plus the joints' in his
// form, and a body meets few joints, so the cliques stay small.
//
// The factor is L L^T with L's diagonal blocks Cholesky factors, so it is
// the scalar Cholesky of A in this order, and its pivots are CHOLMOD's:
// the same positive-definiteness test and pivot ratio. For a chain A is
// block tridiagonal and the factorization is a walk down the chain with
// one small Cholesky per joint; CHOLMOD gives the same numbers up to
// round-off for a general sparse matrix, with a symbolic and a numeric
// phase per call whose fixed costs dominate at these sizes
// (docs/performance.md measures both on chain-100).
#pragma once

#include "constraints/row.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace cairn {

class TreeFactor {
 public:
  // Groups the rows `subset` (indices into `rows`) names by the bodies
  // they couple (dense_system.hpp's couplingBodyA/B) and orders the groups
  // for elimination. False when the groups' bodies hold a cycle (two
  // groups between the same pair of bodies cannot occur: they are one
  // group) or a body meets so many groups that its clique would cost more
  // than a general sparse factorization; the factor is then unusable.
  bool analyse(std::span<const ConstraintRow> rows, std::span<const int> subset);
  bool usable() const { return usable_; }

  // L L^T = A[S, S] + diag(cfm) + shift I, with the pattern analyse saw.
  // False when a pivot is not positive (not positive definite).
  bool factorize(std::span<const ConstraintRow> rows, std::span<const int> subset, double shift);
  // (smallest / largest diagonal entry of L)^2: CHOLMOD's cholmod_rcond
  // for an L L^T factor; 0 when the factorization failed.
  double pivotRatio() const { return pivot_ratio_; }

  // x <- (L L^T)^-1 x, x in the order of `subset`.
  void solveInPlace(std::span<double> x) const;

 private:
  struct Group {
    std::int32_t body[2] = {0, 0};  // the bodies it couples (lo, hi); 0: none
    std::int32_t size = 0;
    std::int32_t rows = 0;         // first entry in pos_
    std::int32_t diag = 0;         // offset of its size x size diagonal block in values_ (row-major)
    std::int32_t next_begin = 0;   // its later neighbours in next_ / below_
    std::int32_t next_end = 0;
    std::int32_t update_begin = 0;  // its Schur updates in update_
    std::int32_t update_end = 0;
  };
  // The update of one pair (i <= k) of a group's later neighbours: block
  // A_ki -= L_k L_i^T, written at `target` (A_ki's offset, row-major
  // size_k x size_i).
  struct Update {
    std::int32_t k, i;  // neighbour slots (into next_/below_)
    std::int32_t target;
  };
  // The most rows one pair of bodies may carry (a six-dof joint with every
  // limit and motor has twelve); past it CHOLMOD takes the island.
  static constexpr int kMaxGroupRows = 24;
  // One group's part of the forward (L y = x) and backward (L^T x = y)
  // substitutions, on the right-hand side in group order.
  template <int M>
  void forwardGroup(const Group& g, double* w) const;
  template <int M>
  void backwardGroup(const Group& g, double* w) const;
  template <int M>
  bool eliminate(const Group& g, std::span<const ConstraintRow> rows, std::span<const int> subset, double shift,
                 double& lo, double& hi);

  bool usable_ = false;
  std::vector<Group> groups_;          // in elimination order
  std::vector<std::int32_t> pos_;      // row positions in subset order, group after group
  std::vector<std::int32_t> next_;     // later neighbour groups, ascending
  std::vector<std::int32_t> below_;    // per next_ entry: offset of L_kg (size_k x size_g, row-major)
  struct Shared {
    std::int32_t slot_g, slot_k;  // the shared body's slot in the group and in the neighbour
  };
  std::vector<Shared> shared_;         // per next_ entry
  std::vector<Update> update_;
  std::vector<double> values_;
  std::vector<double> recip_;          // 1 / L's diagonal entries, in group order
  double pivot_ratio_ = 0;
  // Scratch: the solve's right-hand side in group order (solveInPlace).
  mutable std::vector<double> work_;
};

}  // namespace cairn
