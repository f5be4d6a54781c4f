// Joints side by side in vector lanes.
//
// A joint's rows (a row group, graph_solver.hpp) are solved one after
// another, each row waiting for the last one's body update. Joints of one
// colour share no dynamic body, so up to eight of them with the same number
// of rows can be solved at once, one per lane: row k of every lane in one
// vector operation, as the contact manifolds are (contact_batch.hpp). This
// is the layout of Jolt's and Box2D v3's wide constraint solvers applied to
// cairn's generic rows (constraints/row.hpp): per row its Jacobian, its
// M^-1 J^T, its effective mass and target, in structure-of-arrays form.
//
// Per lane the arithmetic is the scalar row update's (graph_solver.cpp,
// solveGroup) in the same order, without contraction, so a joint solved in
// a lane has the bits it has solved alone: lanes change only how many
// joints are solved at once.
//
// The lanes carry a copy of the rows, made when a solve starts, and keep
// the impulses through its sweeps, with NNCG's changes and directions; the
// impulses go back to the rows when the sweeps end. (Copied in and out
// around each visit instead, the rows' impulses took most of what the
// lanes saved: a row is 288 bytes, so each impulse is a cache line of its
// own.)
#pragma once

#include "solver/contact_batch.hpp"

#include <cstdint>

namespace cairn {

// Row k of every lane of a JointLanes.
struct alignas(64) JointLaneRow {
  using Lanes = double[kBatchLanes];
  Lanes j_lin_a[3], j_ang_a[3], j_lin_b[3], j_ang_b[3];  // J
  Lanes m_lin_a[3], m_ang_a[3], m_lin_b[3], m_ang_b[3];  // M^-1 J^T
  Lanes inv_diag, rhs, cfm, lo, hi;
  Lanes bias_rhs, correction;  // the correction passes' target, and the row's Correction as a number
  Lanes lambda_bias;           // the correction pass's impulse, from zero each pass
  Lanes lambda;  // the impulse, from the row's when the solve starts
  Lanes change;  // NNCG: the last visit's change
  Lanes dir;     // NNCG: the momentum direction
};

// Up to kBatchLanes joints of one colour with the same number of rows and
// no friction row (a friction row's bounds read its normal row's impulse,
// which only a scalar visit keeps in order). An unused lane has group -1,
// the world for both bodies and all-zero rows.
struct alignas(64) JointLanes {
  std::int32_t group[kBatchLanes];   // the lane's row group, -1 for none
  std::int32_t body_a[kBatchLanes];  // solver body indices, the same for all of a group's rows
  std::int32_t body_b[kBatchLanes];
  std::int32_t island[kBatchLanes];
  // Set by the plan, the same for the whole solve: `used` is 1 where the
  // lane holds a joint; `writes_a` and `writes_b` are 1 where, besides, its
  // body a or b is a dynamic solver body (a row update writes its
  // velocity). 0 elsewhere.
  double used[kBatchLanes];
  double writes_a[kBatchLanes];
  double writes_b[kBatchLanes];
  std::int32_t row_begin = 0;  // the first of its `rows` JointLaneRows
  std::int32_t rows = 0;
  double delta[kBatchLanes];   // out: the visit's largest change per lane
  double lambda[kBatchLanes];  // out: and its largest impulse
};

}  // namespace cairn
