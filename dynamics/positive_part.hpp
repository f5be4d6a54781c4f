// The positive semidefinite part of a symmetric 3 x 3 matrix: its
// eigenvalues below zero set to zero, the eigenvectors kept (the nearest
// positive semidefinite matrix in the Frobenius norm; Higham, "Computing a
// nearest symmetric positive semidefinite matrix", Linear Algebra Appl.
// 103, 1988). The geometric stiffness keeps this part of a joint's K
// (world/geometric_stiffness.cpp).
#pragma once

#include "cairn/math.hpp"

namespace cairn {

// The positive part of the symmetric s. Three routes, cheapest first:
// s already semidefinite by Sylvester's criterion, to round-off (returned
// as it is); exactly one negative eigenvalue (found by Newton's method on
// det(s - lambda 1), its eigenvector by a cross product, and
// s - lambda v v^T returned); else Eigen's symmetric eigensolver.
Mat3 positivePart(const Mat3& s);

}  // namespace cairn
