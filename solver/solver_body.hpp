// What the solvers read and write per body: its velocity, in one contiguous
// array indexed by the rows' body indices. Index 0 is the world (always at
// rest; rows give it zero M^-1 J^T so it never moves). Static, kinematic and
// sleeping bodies have zero M^-1 J^T too; a kinematic body's velocity still
// enters J v.
#pragma once

#include "cairn/math.hpp"

namespace cairn {

struct SolverBody {
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
};

}  // namespace cairn
