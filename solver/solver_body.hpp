// What the solvers read and write per body: its velocity, in one contiguous
// array indexed by the rows' body indices, 64 bytes (one cache line) per
// body so a wide kernel loads a body with one aligned access. The step
// orders the array: awake dynamic bodies from index 1, island by island, then the
// kinematic bodies; index 0 stands for the world and every static body (as
// the exact solvers expect). Only the dynamic part is ever written;
// kinematic and static bodies have zero M^-1 J^T and their velocities are
// read only.
#pragma once

#include "cairn/math.hpp"

namespace cairn {

struct alignas(64) SolverBody {
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
  Real spare[2] = {0, 0};  // pads the body to one cache line
};
static_assert(sizeof(SolverBody) == 64, "the contact kernels read 8 doubles per body");

}  // namespace cairn
