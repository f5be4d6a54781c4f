#include "dynamics/positive_part.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace cairn {

namespace {

// det(s - x 1) and its derivative in x, minus the sum of the principal
// 2 x 2 minors of s - x 1: both from the shifted matrix, so near a root
// they carry the round-off of s's entries, not of the characteristic
// polynomial's coefficients.
void shiftedDeterminant(const Mat3& s, Real x, Real& q, Real& dq) {
  const Real a = s(0, 0) - x, d = s(1, 1) - x, f = s(2, 2) - x, b = s(0, 1), c = s(0, 2), e = s(1, 2);
  const Real m_af = a * f - c * c, m_df = d * f - e * e, m_ad = a * d - b * b;
  q = a * m_df - b * (b * f - c * e) + c * (b * e - c * d);
  dq = -(m_ad + m_af + m_df);
}

// The one negative eigenvalue's part removed, when s has exactly one
// (det < 0 < trace) and Newton's method reaches it from zero; false
// otherwise. q(x) = det(s - x 1) is convex for x < trace / 3, so with
// q(0) = det < 0 and q'(0) = -c2 < 0 the first step lands left of the
// root and the next ones climb to it monotonically, quadratically (its
// slope there, -(l2 - l1)(l3 - l1), is not zero: l2 > 0 > l1). From
// zero the error after k steps is about l1 (l1 / l2)^(2^k - 1): a link's
// K (l1 / l2 of order its squared angle off the line) is at round-off
// after three, taken without a test between them so that consecutive
// bodies' chains of divisions overlap; a larger l1 / l2 climbs on. The
// eigenvector is the longest cross product of two rows of s - l1 1
// (orthogonal to all three rows, they span the other eigenvectors);
// when even that one is short, l1 is nearly double and the general
// solver decides.
bool dropOneNegative(const Mat3& s, Real scale, Real det, Real dq0, Mat3& kept) {
  if (!(det < 0) || !(dq0 < 0) || !(s.trace() > 0)) return false;
  Real x = -det / dq0, q, dq;  // the first step: 0 - q(0) / q'(0)
  for (int it = 0; it < 2; ++it) {
    shiftedDeterminant(s, x, q, dq);
    x -= q / dq;
  }
  for (int it = 0; it < 64; ++it) {
    shiftedDeterminant(s, x, q, dq);
    if (!(dq < 0)) return false;
    const Real step = q / dq;  // < 0 while it climbs
    if (!(step < -Real(1e-15) * scale)) break;
    x -= step;
  }
  const Mat3 m = s - x * Mat3::Identity();
  const Vec3 r0 = m.row(0).transpose(), r1 = m.row(1).transpose(), r2 = m.row(2).transpose();
  const Vec3 c[3] = {r0.cross(r1), r0.cross(r2), r1.cross(r2)};
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (c[i].squaredNorm() > c[best].squaredNorm()) best = i;
  const Real n2 = c[best].squaredNorm();
  // |c| >= 1e-8 scale^2: v's round-off error is then below 1e-8, and
  // kept's below 1e-8 |l1|.
  if (!(n2 >= Real(1e-16) * scale * scale * scale * scale)) return false;
  kept = s - (x / n2) * (c[best] * c[best].transpose());
  return true;
}

// Every principal minor of the symmetric s is >= 0 (the three diagonal
// entries, the three 2 x 2 minors and the determinant), each to round-off
// relative to s's largest entry: a stretched joint's K has an exact zero
// eigenvalue (along the link), which round-off leaves at +-1e-16 of the
// others, and keeping a part that small changes nothing it can show.
bool positiveSemidefinite(const Mat3& s, Real scale) {
  const Real a = s(0, 0), d = s(1, 1), f = s(2, 2), b = s(0, 1), c = s(0, 2), e = s(1, 2);
  const Real tol = Real(1e-12) * scale;
  return a >= -tol && d >= -tol && f >= -tol && a * d - b * b >= -tol * scale && a * f - c * c >= -tol * scale &&
         d * f - e * e >= -tol * scale && s.determinant() >= -tol * scale * scale;
}

}  // namespace

Mat3 positivePart(const Mat3& s) {
  const Real scale = s.cwiseAbs().maxCoeff();
  if (positiveSemidefinite(s, scale)) return s;
  Real det, dq0;
  shiftedDeterminant(s, 0, det, dq0);
  Mat3 kept;
  if (dropOneNegative(s, scale, det, dq0, kept)) return kept;
  const Eigen::SelfAdjointEigenSolver<Mat3> es(s);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(Real(0)).asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace cairn
