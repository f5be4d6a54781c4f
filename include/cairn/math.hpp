/// @file
/// Scalar and vector aliases used everywhere in cairn, and the few rotation
/// helpers the integrators and constraint parts share.
///
/// cairn computes in double precision (Real = double) so that it can be
/// compared with Bullet's float64 build without a precision gap.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>  // vec3's paired store (Eigen includes it only when it vectorizes)
#endif

namespace cairn {

using Real = double;  ///< every scalar: double precision
using Vec3 = Eigen::Matrix<Real, 3, 1>;  ///< 3-vector (m, m/s, N, ...)
using Vec4 = Eigen::Matrix<Real, 4, 1>;  ///< 4-vector
using Mat3 = Eigen::Matrix<Real, 3, 3>;  ///< 3x3 matrix (rotations, inertia tensors)
using Quat = Eigen::Quaternion<Real>;  ///< unit quaternion: Quat(w, x, y, z), rotates v as q * v

inline constexpr Real kInf = std::numeric_limits<Real>::infinity();  ///< infinity: no limit
inline constexpr Real kPi = 3.14159265358979323846;  ///< pi

/// Cross-product matrix: skew(a) * b == a.cross(b).
inline Mat3 skew(const Vec3& a) {
  Mat3 m;
  m << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return m;
}

namespace math_detail {
// A 3-vector from its components, its first two written as one pair.
// Eigen reads a Vec3 as a pair (x, y) and a single z; a vector written
// one component at a time and read back at once as a pair is a store the
// processor cannot forward (a stall of a dozen cycles or so).
inline Vec3 vec3(Real x, Real y, Real z) {
  Vec3 r;
#if defined(__SSE2__)
  _mm_storeu_pd(r.data(), _mm_set_pd(y, x));
  r.z() = z;
#else
  r = Vec3(x, y, z);
#endif
  return r;
}

struct Components {
  Real x, y, z;
};
// Eigen's q * v (uv = 2 (q_vec x v); v + w uv + q_vec x uv), the same
// operations in the same order, so the same bits, by component.
inline Components rotated(const Quat& q, const Vec3& v) {
  const Real x = q.x(), y = q.y(), z = q.z(), w = q.w();
  Real ux = y * v.z() - z * v.y(), uy = z * v.x() - x * v.z(), uz = x * v.y() - y * v.x();
  ux += ux;
  uy += uy;
  uz += uz;
  return {v.x() + w * ux + (y * uz - z * uy), v.y() + w * uy + (z * ux - x * uz), v.z() + w * uz + (x * uy - y * ux)};
}
}  // namespace math_detail

/// q * v, the rotation of v by the unit quaternion q, bit for bit. Written
/// out by component because Eigen's own form stores its intermediate a
/// component at a time and reads it back as a pair (math_detail::vec3): a stall at
/// every rotation of a joint's anchors.
inline Vec3 rotate(const Quat& q, const Vec3& v) {
  const math_detail::Components r = math_detail::rotated(q, v);
  return math_detail::vec3(r.x, r.y, r.z);
}

/// p + q * v (a body's point in the world), bit for bit.
inline Vec3 rotateAdd(const Vec3& p, const Quat& q, const Vec3& v) {
  const math_detail::Components r = math_detail::rotated(q, v);
  return math_detail::vec3(p.x() + r.x, p.y() + r.y, p.z() + r.z);
}

/// Exponential map (section 12.6.4): the unit quaternion of a rotation by
/// |theta| radians about theta / |theta|. Below 1e-8 rad the Taylor series of
/// sin(x/2)/x keeps the result exact to round-off instead of dividing by ~0.
inline Quat quatFromRotationVector(const Vec3& theta) {
  const Real angle = theta.norm();
  const Real half = Real(0.5) * angle;
  const Real s = angle < Real(1e-8) ? Real(0.5) - angle * angle / Real(48)
                                    : std::sin(half) / angle;
  return Quat(std::cos(half), s * theta.x(), s * theta.y(), s * theta.z());
}

/// Inverse of quatFromRotationVector for a unit quaternion: the rotation
/// vector of the shortest rotation (angle in [0, pi]).
inline Vec3 rotationVectorFromQuat(const Quat& q_in) {
  Quat q = q_in;
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Vec3 v = q.vec();
  const Real s = v.norm();
  if (s < Real(1e-12)) return Real(2) * v;  ///< small-angle limit
  const Real angle = Real(2) * std::atan2(s, q.w());
  return v * (angle / s);
}

inline bool allFinite(const Vec3& v) { return v.allFinite(); }  ///< no NaN or infinity
inline bool allFinite(const Quat& q) { return q.coeffs().allFinite(); }  ///< no NaN or infinity
inline bool allFinite(const Mat3& m) { return m.allFinite(); }  ///< no NaN or infinity

/// Any unit vector perpendicular to n (n need not be unit). Used for
/// friction tangents and joint reference axes.
inline Vec3 anyPerpendicular(const Vec3& n) {
  const Vec3 a = std::abs(n.x()) < Real(0.57735) ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(a).normalized();
}

/// A rigid transform: world point = p + R * local.
struct Transform {
  Vec3 p = Vec3::Zero();  ///< translation (m)
  Quat q = Quat::Identity();  ///< rotation

  Vec3 apply(const Vec3& local) const { return rotateAdd(p, q, local); }  ///< local point to world
  Vec3 applyInverse(const Vec3& world) const { return rotate(q.conjugate(), world - p); }  ///< world point to local
  Transform operator*(const Transform& child) const {  ///< this after child: child frame to world
    return Transform{apply(child.p), (q * child.q).normalized()};
  }
};

}  // namespace cairn
