// Hand-built row systems for the exact, direct, residual and assembly
// tests: bodies with known inverse masses, rows with consistent
// M^-1 J^T blocks, and an explicit J / M^-1 to check against.
#pragma once

#include "constraints/row.hpp"
#include "solver/solver_body.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace cairn::exact_test {

struct BodyMass {
  Real inv_mass = 0;                  // 0: world, static or kinematic
  Mat3 inv_inertia = Mat3::Zero();
};

inline Real uniform(std::mt19937& rng, Real lo, Real hi) { return std::uniform_real_distribution<Real>(lo, hi)(rng); }
inline Vec3 randomVec(std::mt19937& rng, Real scale = 1) {
  return Vec3(uniform(rng, -scale, scale), uniform(rng, -scale, scale), uniform(rng, -scale, scale));
}
// R diag(e) R^T with eigenvalues in [lo, hi]: a random SPD inertia.
inline Mat3 randomSpd(std::mt19937& rng, Real lo, Real hi) {
  const Quat q = Quat(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)).normalized();
  const Mat3 r = q.toRotationMatrix();
  const Vec3 e(uniform(rng, lo, hi), uniform(rng, lo, hi), uniform(rng, lo, hi));
  return r * e.asDiagonal() * r.transpose();
}

struct RowSystem {
  std::vector<BodyMass> mass{BodyMass{}};          // index 0 = the world
  std::vector<SolverBody> bodies{SolverBody{}};

  std::vector<ConstraintRow> rows;

  int addBody(Real inv_mass, const Mat3& inv_inertia, const Vec3& v = Vec3::Zero(), const Vec3& w = Vec3::Zero()) {
    mass.push_back(BodyMass{inv_mass, inv_inertia});
    bodies.push_back(SolverBody{v, w});
    return static_cast<int>(bodies.size()) - 1;
  }

  // A row with Jacobian blocks for a and b; M^-1 J^T and inv_diag are
  // computed from the bodies' masses (so they are consistent).
  ConstraintRow& addRow(int a, int b, const Vec3& jla, const Vec3& jaa, const Vec3& jlb, const Vec3& jab) {
    ConstraintRow r;
    r.body_a = a;
    r.body_b = b;
    r.j_lin_a = jla;
    r.j_ang_a = jaa;
    r.j_lin_b = jlb;
    r.j_ang_b = jab;
    const BodyMass& ma = mass[static_cast<std::size_t>(a)];
    const BodyMass& mb = mass[static_cast<std::size_t>(b)];
    r.m_lin_a = ma.inv_mass * jla;
    r.m_ang_a = ma.inv_inertia * jaa;
    r.m_lin_b = mb.inv_mass * jlb;
    r.m_ang_b = mb.inv_inertia * jab;
    rows.push_back(r);
    refreshDiag(rows.back());
    return rows.back();
  }

  // inv_diag = 1 / (J M^-1 J^T + cfm), summing both sides when a == b.
  void refreshDiag(ConstraintRow& r) const {
    Real d = r.cfm;
    auto side = [](const Vec3& jl, const Vec3& ja, const Vec3& ml, const Vec3& ma) { return jl.dot(ml) + ja.dot(ma); };
    if (r.body_a == r.body_b) {
      if (r.body_a != 0) d += side(r.j_lin_a + r.j_lin_b, r.j_ang_a + r.j_ang_b, r.m_lin_a + r.m_lin_b, r.m_ang_a + r.m_ang_b);
    } else {
      if (r.body_a != 0) d += side(r.j_lin_a, r.j_ang_a, r.m_lin_a, r.m_ang_a);
      if (r.body_b != 0) d += side(r.j_lin_b, r.j_ang_b, r.m_lin_b, r.m_ang_b);
    }
    r.inv_diag = d > 0 ? 1 / d : 0;
  }
  void setCfm(ConstraintRow& r, Real cfm) const {
    r.cfm = cfm;
    refreshDiag(r);
  }

  // A point (world offset ra from a, rb from b) kept coincident along e:
  // Cdot = e . (v_b + w_b x rb - v_a - w_a x ra).
  ConstraintRow& addPointRow(int a, int b, const Vec3& ra, const Vec3& rb, const Vec3& e) {
    return addRow(a, b, -e, -ra.cross(e), e, rb.cross(e));
  }

  // Ball joint: three point rows along x, y, z.
  void addBall(int a, int b, const Vec3& ra, const Vec3& rb, Real rhs_scale, std::mt19937& rng) {
    for (int k = 0; k < 3; ++k) addPointRow(a, b, ra, rb, Vec3::Unit(k)).rhs = uniform(rng, -rhs_scale, rhs_scale);
  }

  // A contact of body b on the world at lever arm r with normal n: the
  // normal row (lo = 0) and, when mu > 0, two friction rows that point at it.
  int addContact(int b, const Vec3& r, const Vec3& n_in, Real mu, Real rhs) {
    const Vec3 n = n_in.normalized();
    ConstraintRow& nr = addRow(0, b, Vec3::Zero(), Vec3::Zero(), n, r.cross(n));
    nr.lo = 0;
    nr.hi = kInf;
    nr.rhs = rhs;
    nr.kind = RowKind::ContactNormal;
    const int normal = static_cast<int>(rows.size()) - 1;
    if (mu > 0) {
      const Vec3 t1 = anyPerpendicular(n);
      const Vec3 t2 = n.cross(t1);
      for (const Vec3& t : {t1, t2}) {
        ConstraintRow& f = addRow(0, b, Vec3::Zero(), Vec3::Zero(), t, r.cross(t));
        f.normal_row = normal;
        f.mu = mu;
        f.kind = RowKind::ContactFriction;
      }
    }
    return normal;
  }

  // The explicit J (rows x 6 bodies) and block-diagonal M^-1, world
  // included as body 0 (zero inverse mass).
  Eigen::MatrixXd jacobian() const {
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), 6 * static_cast<Eigen::Index>(bodies.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const ConstraintRow& r = rows[i];
      const auto row = static_cast<Eigen::Index>(i);
      j.block<1, 3>(row, 6 * r.body_a) += r.j_lin_a.transpose();
      j.block<1, 3>(row, 6 * r.body_a + 3) += r.j_ang_a.transpose();
      j.block<1, 3>(row, 6 * r.body_b) += r.j_lin_b.transpose();
      j.block<1, 3>(row, 6 * r.body_b + 3) += r.j_ang_b.transpose();
    }
    return j;
  }
  Eigen::MatrixXd inverseMass() const {
    const auto nb = static_cast<Eigen::Index>(bodies.size());
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(6 * nb, 6 * nb);
    for (Eigen::Index k = 1; k < nb; ++k) {
      m.block<3, 3>(6 * k, 6 * k) = mass[static_cast<std::size_t>(k)].inv_mass * Mat3::Identity();
      m.block<3, 3>(6 * k + 3, 6 * k + 3) = mass[static_cast<std::size_t>(k)].inv_inertia;
    }
    return m;
  }
  Eigen::VectorXd velocityVector() const {
    Eigen::VectorXd v(6 * static_cast<Eigen::Index>(bodies.size()));
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      v.segment<3>(6 * static_cast<Eigen::Index>(k)) = bodies[k].v;
      v.segment<3>(6 * static_cast<Eigen::Index>(k) + 3) = bodies[k].w;
    }
    return v;
  }
  Eigen::VectorXd cfmVector() const {
    Eigen::VectorXd c(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) c(static_cast<Eigen::Index>(i)) = rows[i].cfm;
    return c;
  }
  Eigen::VectorXd lambdaVector() const {
    Eigen::VectorXd l(static_cast<Eigen::Index>(rows.size()));
    for (std::size_t i = 0; i < rows.size(); ++i) l(static_cast<Eigen::Index>(i)) = rows[i].lambda;
    return l;
  }
};

// n point masses on a line, each linked to the previous one (the first to
// the world) by a 1-D distance-like row along x. Odd rows list the bodies
// the other way round (body_a of one row is body_b of the next).
inline RowSystem pointMassChain(int n, std::mt19937& rng) {
  RowSystem s;
  for (int k = 0; k < n; ++k) {
    const int id = s.addBody(1 / uniform(rng, 0.5, 3.0), Mat3::Zero(), randomVec(rng));
    const int prev = id - 1;
    ConstraintRow& r = k % 2 == 0 ? s.addRow(prev, id, -Vec3::UnitX(), Vec3::Zero(), Vec3::UnitX(), Vec3::Zero())
                                  : s.addRow(id, prev, Vec3::UnitX(), Vec3::Zero(), -Vec3::UnitX(), Vec3::Zero());
    r.rhs = uniform(rng, -0.5, 0.5);
  }
  return s;
}

// A hanging 3-D chain of rigid bodies with random masses and SPD inertias,
// each linked to the previous one (the first to the world) by a ball joint
// at random lever arms; random initial velocities.
inline RowSystem rigidChain(int n, std::mt19937& rng) {
  RowSystem s;
  for (int k = 0; k < n; ++k) {
    const Mat3 inertia = randomSpd(rng, 0.05, 0.5);
    const int id = s.addBody(1 / uniform(rng, 0.5, 3.0), inertia.inverse(), randomVec(rng), randomVec(rng));
    s.addBall(id - 1, id, randomVec(rng, 0.5), randomVec(rng, 0.5), 0.2, rng);
  }
  return s;
}

// Explicit statement of the complementarity conditions, independent of
// lcp_residual: for each row the smallest violation among the three
// branches (at lo with w >= 0, at hi with w <= 0, inside with w = 0), with
// friction bounds -+ mu |lambda_normal|. Returns the largest over rows.
inline Real complementarityViolation(const Eigen::MatrixXd& a_with_cfm, const Eigen::VectorXd& b,
                                     const Eigen::VectorXd& lambda, const Eigen::VectorXd& lo_in,
                                     const Eigen::VectorXd& hi_in, const std::vector<int>& normal,
                                     const Eigen::VectorXd& mu) {
  const Eigen::VectorXd w = a_with_cfm * lambda + b;
  Real worst = 0;
  for (Eigen::Index i = 0; i < lambda.size(); ++i) {
    Real lo = lo_in(i), hi = hi_in(i);
    const int nr = normal.empty() ? -1 : normal[static_cast<std::size_t>(i)];
    if (nr >= 0) {
      hi = std::abs(mu(i) * lambda(nr));
      lo = -hi;
    }
    const Real x = lambda(i);
    const Real at_lo = lo > -kInf ? std::max(std::abs(x - lo), std::max(Real(0), -w(i))) : kInf;
    const Real at_hi = hi < kInf ? std::max(std::abs(x - hi), std::max(Real(0), w(i))) : kInf;
    const Real inside = std::max({std::abs(w(i)), lo - x, x - hi, Real(0)});
    worst = std::max(worst, std::min({at_lo, at_hi, inside}));
  }
  return worst;
}

// The same for a row system after a solve: A and b from the explicit J,
// M^-1 and the given impulse-free velocities v*.
inline Real complementarityViolation(const RowSystem& s, const std::vector<SolverBody>& v_star) {
  RowSystem before = s;
  before.bodies = v_star;
  const Eigen::MatrixXd j = s.jacobian();
  const Eigen::MatrixXd a = j * s.inverseMass() * j.transpose() + Eigen::MatrixXd(s.cfmVector().asDiagonal());
  Eigen::VectorXd b = j * before.velocityVector();
  Eigen::VectorXd lo(b.size()), hi(b.size()), mu(b.size());
  std::vector<int> normal(s.rows.size());
  for (std::size_t i = 0; i < s.rows.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    b(k) -= s.rows[i].rhs;
    lo(k) = s.rows[i].lo;
    hi(k) = s.rows[i].hi;
    mu(k) = s.rows[i].mu;
    normal[i] = s.rows[i].normal_row;
  }
  return complementarityViolation(a, b, s.lambdaVector(), lo, hi, normal, mu);
}

// Largest |v - (v* + M^-1 J^T lambda)| over the bodies' velocity entries.
inline Real velocityMismatch(const RowSystem& s, const std::vector<SolverBody>& v_star) {
  RowSystem before = s;
  before.bodies = v_star;
  const Eigen::VectorXd expect = before.velocityVector() + s.inverseMass() * s.jacobian().transpose() * s.lambdaVector();
  return (s.velocityVector() - expect).lpNorm<Eigen::Infinity>();
}

}  // namespace cairn::exact_test
