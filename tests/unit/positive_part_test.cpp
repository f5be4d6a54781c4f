// The positive semidefinite part of a symmetric 3 x 3 matrix
// (dynamics/positive_part.hpp), checked against the closed form: for
// s = Q diag(l) Q^T with Q a rotation, the part is Q diag(max(l, 0)) Q^T.
// Each route is a few dozen floating-point operations on the entries, so
// its error is round-off, a few 1e-16 of the largest eigenvalue (2.4e-15
// at worst measured, Eigen's iterative solver); 1e-13 leaves a factor 40.
// A closed-form eigensolver (Eigen's computeDirect) misses it by 1e-8
// where two eigenvalues are equal, as a stretched link's are.
#include "dynamics/positive_part.hpp"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <random>

namespace cairn {
namespace {

Mat3 randomRotation(std::mt19937& rng) {
  std::normal_distribution<Real> g(0, 1);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

struct Case {
  Vec3 l;  // eigenvalues
  const char* what;
};

TEST(PositivePart, EqualsTheEigenvaluesClampedAtZeroOnEveryRoute) {
  const Case cases[] = {
      {{0.5, 2, 3}, "positive definite: returned as it is"},
      {{0, 1, 1}, "a stretched link's K: one exact zero, a double eigenvalue"},
      {{-1e-3, 2, 3}, "one small negative eigenvalue: Newton's route"},
      {{-0.4, 1, 1}, "one negative, the others equal: Newton's route"},
      {{-5, 1, 2}, "one large negative eigenvalue (trace < 0): the eigensolver"},
      {{-1, 0.5, 3}, "one negative, c2 < 0: the eigensolver"},
      {{-1, -2, 3}, "two negative: the eigensolver"},
      {{-1, -2, -3}, "negative definite: zero"},
  };
  std::mt19937 rng(7);
  for (const Case& c : cases) {
    for (int trial = 0; trial < 50; ++trial) {
      const Mat3 q = randomRotation(rng);
      const Real scale = std::exp(std::uniform_real_distribution<Real>(-6, 6)(rng));  // 1e-3 to 4e2
      const Mat3 s = q * (scale * c.l).asDiagonal() * q.transpose();
      const Mat3 want = q * (scale * c.l.cwiseMax(Real(0))).asDiagonal() * q.transpose();
      const Mat3 got = positivePart(Real(0.5) * (s + s.transpose()));
      const Real tol = Real(1e-13) * scale * c.l.cwiseAbs().maxCoeff();
      EXPECT_LE((got - want).cwiseAbs().maxCoeff(), tol) << c.what << ", trial " << trial;
      EXPECT_LE((got - got.transpose()).cwiseAbs().maxCoeff(), tol) << c.what;
    }
  }
}

// A chain link pulled at its two anchors r and -r by forces whose sum d is
// off the link's line: K = (d.r) 1 - (r d^T + d r^T) / 2 has eigenvalues
// d.r (normal to both), and (d.r +- |r||d|) / 2 in their plane, the minus
// one negative for any angle between them: the case the geometric
// stiffness meets at almost every link of a swinging chain.
TEST(PositivePart, DropsTheNegativeEigenvalueOfALinkPulledOffItsLine) {
  std::mt19937 rng(11);
  std::normal_distribution<Real> g(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 r = Vec3(g(rng), g(rng), g(rng)).normalized() * Real(0.25);
    const Vec3 d = 100 * r.normalized() + Vec3(g(rng), g(rng), g(rng));  // tension, and a few N off the line
    const Mat3 k = d.dot(r) * Mat3::Identity() - Real(0.5) * (r * d.transpose() + d * r.transpose());
    const Real rd = r.norm() * d.norm();
    const Mat3 got = positivePart(k);
    Eigen::SelfAdjointEigenSolver<Mat3> es(got);
    const Vec3 want = Vec3(0, (d.dot(r) + rd) / 2, d.dot(r)).cwiseMax(Real(0));
    Vec3 sorted = want;
    std::sort(sorted.data(), sorted.data() + 3);
    EXPECT_LE((es.eigenvalues() - sorted).cwiseAbs().maxCoeff(), Real(1e-13) * rd) << "trial " << trial;
  }
}

}  // namespace
}  // namespace cairn
