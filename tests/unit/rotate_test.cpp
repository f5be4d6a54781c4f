// rotate and rotateAdd (include/cairn/math.hpp) stand in for Eigen's q * v
// on the step's hot paths. They must give Eigen's result bit for bit:
// the engine's trajectories, and the contact kernels that repeat Eigen's
// order of operations, were measured and pinned on it.
#include "cairn/math.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

namespace cairn {
namespace {

bool sameBits(const Vec3& a, const Vec3& b) { return std::memcmp(a.data(), b.data(), sizeof(double) * 3) == 0; }

TEST(Rotate, GivesEigensQuaternionProductBitForBit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  std::uniform_real_distribution<Real> scale(-40, 40);
  for (int k = 0; k < 20000; ++k) {
    const Quat q = Quat(u(rng), u(rng), u(rng), u(rng)).normalized();
    // Magnitudes from 1e-12 to 1e12, some components exactly zero or
    // negative zero (the sign of a zero is a bit too).
    Vec3 v(u(rng) * std::pow(Real(10), scale(rng) / 3), u(rng) * std::pow(Real(10), scale(rng) / 3),
           u(rng) * std::pow(Real(10), scale(rng) / 3));
    if (k % 7 == 0) v.x() = 0;
    if (k % 11 == 0) v.z() = -0.0;
    const Vec3 p(scale(rng), scale(rng), scale(rng));
    const Vec3 eigen = q * v;
    ASSERT_TRUE(sameBits(rotate(q, v), eigen)) << "q = " << q.coeffs().transpose() << ", v = " << v.transpose();
    const Vec3 eigen_point = p + q * v;
    ASSERT_TRUE(sameBits(rotateAdd(p, q, v), eigen_point));
    const Transform t{p, q};
    ASSERT_TRUE(sameBits(t.apply(v), eigen_point));
    const Vec3 eigen_back = q.conjugate() * (v - p);
    ASSERT_TRUE(sameBits(t.applyInverse(v), eigen_back));
  }
}

TEST(Rotate, Vec3HoldsItsComponents) {
  const Vec3 v = math_detail::vec3(1.5, -0.0, 3e-300);
  EXPECT_EQ(v.x(), 1.5);
  EXPECT_TRUE(std::signbit(v.y()));
  EXPECT_EQ(v.z(), 3e-300);
}

}  // namespace
}  // namespace cairn
