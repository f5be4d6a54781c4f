// Dantzig's principal pivoting for the box-bounded mixed LCP (see the
// header). Notation: w = A x + b; C = clamped rows (w = 0, kept solved by a
// Cholesky factor of A[C, C]); N = rows at a bound; free = rows not yet
// driven, whose x stays at its start value and whose w is not watched.
//
// Driving row d in direction dir = -sign(w_d) by a step t moves
//     x_d += t dir,   x_C += t dx_C with dx_C = -dir A[C,C]^-1 A[C,d],
// which keeps w_C = 0 and changes every w by t dw, dw = A dx. The ratio
// test takes the smallest t at which w_d reaches 0 (d joins C), x_d reaches
// its bound (d joins N), a clamped x_j reaches a bound (j leaves C for N)
// or a bound row's w_j reaches 0 from its allowed side (j leaves N for C).
// The first two end the drive; the other two repeat it with the new sets.
#include "solver/lcp_exact.hpp"

#include <Eigen/LU>

#include "solver/dense_system.hpp"
#include "solver/lcp_residual.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace cairn {

namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kInfD = std::numeric_limits<double>::infinity();
// Ratio-test thresholds (relative): a clamped row whose |dx_j| per unit of
// dx_d is below kTinyStep, or a bound row whose |dw_j| is below kTinyStep
// times the largest diagonal of A, does not limit the step. Such entries
// are round-off of an exact zero; letting them limit the step would make
// zero-length pivots that can cycle. Ignoring a genuinely tiny one moves
// that row past its bound by round-off, which the next drive repairs.
constexpr double kTinyStep = 1e-13;
// Newton steps on the natural map tried after each pass.
constexpr int kNewtonSteps = 8;

// Cholesky factor L (L L^T = A[C, C]) kept while C changes one row at a
// time. Eigen factors and solves; what Eigen does not offer is changing the
// factored set, so bordering (insertion) and the rank-one update after a
// deletion are written here, O(|C|^2) each.
class ClampedFactor {
 public:
  // Ready for problems of n rows. Every vector and matrix here keeps its
  // storage from solve to solve while n stays the same (Eigen's dynamic
  // objects reallocate on any change of size): the step's exact solve
  // allocates nothing once warm.
  void reset(Index n) {
    l_.resize(n, n);
    z_.resize(n);
    x_.resize(n);
    clear();
  }

  Index size() const { return m_; }
  int updates() const { return updates_; }
  void clear() {
    m_ = 0;
    updates_ = 0;
  }

  // Borders L with a new last row for a = A[C, k] (in C order, the first
  // size() entries of `a`) and akk = A_kk. Fails, leaving L unchanged,
  // when the Schur complement akk - |L^-1 a|^2 is not above min_pivot (k
  // depends linearly on C).
  bool append(const VectorXd& a, double akk, double min_pivot) {
    auto z = z_.head(m_);
    z = a.head(m_);
    if (m_ > 0) l_.topLeftCorner(m_, m_).triangularView<Eigen::Lower>().solveInPlace(z);
    const double d2 = akk - z.squaredNorm();
    if (!(d2 > min_pivot)) return false;
    l_.row(m_).head(m_) = z.transpose();
    l_(m_, m_) = std::sqrt(d2);
    ++m_;
    ++updates_;
    return true;
  }

  // Deletes position p. With L = [L11 0 0; l21' l22 0; L31 l32 L33], the
  // reduced matrix's factor is [L11 0; L31 L33'] with
  // L33' L33'^T = L33 L33^T + l32 l32^T: a rank-one update.
  void remove(Index p) {
    const Index r = m_ - 1 - p;
    if (r > 0) {
      auto x = x_.head(r);
      x = l_.col(p).segment(p + 1, r);
      // Rows p+1.. up by one (and, right of column p, left by one), in
      // place: each entry is read before its own place is written.
      for (Index j = 0; j < p; ++j)
        for (Index i = 0; i < r; ++i) l_(p + i, j) = l_(p + i + 1, j);
      for (Index j = 0; j < r; ++j)
        for (Index i = 0; i < r; ++i) l_(p + i, p + j) = l_(p + i + 1, p + j + 1);
      for (Index k = 0; k < r; ++k) {
        const Index kk = p + k;
        const double lkk = l_(kk, kk);
        const double rad = std::hypot(lkk, x(k));
        const double c = rad / lkk, s = x(k) / lkk;
        l_(kk, kk) = rad;
        const Index tail = r - k - 1;
        if (tail > 0) {
          auto col = l_.col(kk).segment(kk + 1, tail);
          auto xs = x.segment(k + 1, tail);
          col = (col + s * xs) / c;
          xs = c * xs - s * col;
        }
      }
    }
    --m_;
    ++updates_;
  }

  // x := A[C, C]^-1 x (x of size() entries).
  void solveInPlace(Eigen::Ref<VectorXd> x) const {
    const auto lm = l_.topLeftCorner(m_, m_);
    lm.triangularView<Eigen::Lower>().solveInPlace(x);
    lm.transpose().triangularView<Eigen::Upper>().solveInPlace(x);
  }

 private:
  MatrixXd l_;
  VectorXd z_, x_;  // append's and remove's scratch
  Index m_ = 0;
  int updates_ = 0;
};

enum class RowState : std::uint8_t { Free, Clamped, AtLo, AtHi };
enum class PassStatus { Ok, Singular, Failed };

// The problem as one pass sees it. A may carry the regularization.
struct Problem {
  const MatrixXd* A = nullptr;
  const VectorXd* b = nullptr;
  VectorXd lo, hi;          // friction rows' entries are replaced per pass
  std::vector<int> normal;  // normal row of a friction row, else -1
  VectorXd mu;
  std::vector<int> order;   // unbounded rows, bounded rows, friction rows
  Index num_unbounded = 0;
  double singular_pivot = 0;  // relative; 0 once regularized (then only > 0 is required)
  double tiny_dw = 0;
  int max_pivots = 0;
};

// w := A x + b, as (A x)_i + b_i (the product into w, then b: the order
// Eigen gave A x + b, without its temporary).
void residualVelocity(const MatrixXd& a, const VectorXd& b, const VectorXd& x, VectorXd& w) {
  w.noalias() = a * x;
  w += b;
}

// A pass's storage, kept by the solver's workspace from solve to solve.
struct PassScratch {
  ClampedFactor factor;
  VectorXd x, lo, hi;
  VectorXd col, r, w, dw, dxc;  // A[C, k], refineClamped's residual, drive's w, dw and dx_C
  std::vector<RowState> state;
  std::vector<int> clamped, refactor;
};

class DantzigPass {
 public:
  DantzigPass(const Problem& pb, PassScratch& s)
      : x(s.x), lo(s.lo), hi(s.hi), pb_(pb), a_(*pb.A), b_(*pb.b), n_(pb.b->size()), factor_(s.factor),
        state_(s.state), clamped_(s.clamped), refactor_(s.refactor), col_(s.col), r_(s.r), w_(s.w), dw_(s.dw),
        dxc_(s.dxc) {
    factor_.reset(n_);
    for (VectorXd* v : {&x, &lo, &hi, &col_, &r_, &w_, &dw_, &dxc_}) v->resize(n_);
    clamped_.reserve(static_cast<std::size_t>(n_));
    refactor_.reserve(static_cast<std::size_t>(n_));
  }

  // One complete solve with the friction bounds taken from `friction_source`
  // (fixed for the pass) or, when null, from x itself when the first
  // friction row is reached (ODE). Leaves x, lo, hi for the caller.
  PassStatus run(const VectorXd* friction_source, int& pivots) {
    lo = pb_.lo;
    hi = pb_.hi;
    x.setZero(n_);
    for (Index i = 0; i < n_; ++i) {
      if (pb_.normal[static_cast<std::size_t>(i)] < 0) x(i) = std::clamp(0.0, lo(i), hi(i));
    }
    bool friction_set = false;
    if (friction_source != nullptr) {
      setFrictionBounds(*friction_source);
      friction_set = true;
    }
    state_.assign(static_cast<std::size_t>(n_), RowState::Free);
    clamped_.clear();
    factor_.clear();

    // Unbounded rows: all clamped, solved as equalities.
    for (Index k = 0; k < pb_.num_unbounded; ++k) {
      if (!addToClamped(pb_.order[static_cast<std::size_t>(k)])) return PassStatus::Singular;
    }
    refineClamped();

    for (Index k = pb_.num_unbounded; k < n_; ++k) {
      const int d = pb_.order[static_cast<std::size_t>(k)];
      if (!friction_set && pb_.normal[static_cast<std::size_t>(d)] >= 0) {
        setFrictionBounds(x);
        friction_set = true;
      }
      const double wd = a_.col(d).dot(x) + b_(d);
      if (x(d) <= lo(d) && wd >= 0) {
        x(d) = lo(d);
        state_[static_cast<std::size_t>(d)] = RowState::AtLo;
      } else if (x(d) >= hi(d) && wd <= 0) {
        x(d) = hi(d);
        state_[static_cast<std::size_t>(d)] = RowState::AtHi;
      } else if (wd == 0) {
        if (!addToClamped(d)) return PassStatus::Singular;
      } else {
        const PassStatus st = drive(d, pivots);
        if (st != PassStatus::Ok) return st;
      }
      if (factor_.updates() > std::max<Index>(64, 2 * factor_.size())) {
        if (!refactor()) return PassStatus::Singular;
      }
    }
    refineClamped();
    refineClamped();
    for (Index i = 0; i < n_; ++i) x(i) = std::clamp(x(i), lo(i), hi(i));
    return PassStatus::Ok;
  }

  RowState state(Index i) const { return state_[static_cast<std::size_t>(i)]; }

  VectorXd &x, &lo, &hi;

 private:
  enum class Event { None, DriveToC, DriveToLo, DriveToHi, ClampedToLo, ClampedToHi, BoundToC };

  double minPivot(int k) const { return pb_.singular_pivot * std::abs(a_(k, k)); }

  void setFrictionBounds(const VectorXd& source) {
    for (Index i = 0; i < n_; ++i) {
      const int nr = pb_.normal[static_cast<std::size_t>(i)];
      if (nr < 0) continue;
      const double h = std::abs(pb_.mu(i) * source(nr));
      lo(i) = -h;
      hi(i) = h;
    }
  }

  bool addToClamped(int k) {
    const auto m = static_cast<Index>(clamped_.size());
    for (Index c = 0; c < m; ++c) col_(c) = a_(clamped_[static_cast<std::size_t>(c)], k);
    if (!factor_.append(col_, a_(k, k), minPivot(k))) return false;
    clamped_.push_back(k);
    state_[static_cast<std::size_t>(k)] = RowState::Clamped;
    return true;
  }

  // Refactors A[C, C] from scratch, bounding the round-off that successive
  // updates accumulate.
  bool refactor() {
    refactor_.assign(clamped_.begin(), clamped_.end());
    clamped_.clear();
    factor_.clear();
    for (int k : refactor_) {
      if (!addToClamped(k)) return false;
    }
    return true;
  }

  // x_C := the values that make w_C = 0 given every other x (one Newton
  // step on the linear equations, i.e. an exact re-solve).
  void refineClamped() {
    if (clamped_.empty()) return;
    // r = A[:, C]^T x + b[C], by index (Eigen's indexed views copy the
    // index list, an allocation each). The arithmetic of Eigen's product
    // of an indexed view: per entry, the products summed in row order, added
    // to a zeroed result, then b.
    const auto m = static_cast<Index>(clamped_.size());
    auto r = r_.head(m);
    for (Index c = 0; c < m; ++c) {
      const auto col = a_.col(clamped_[static_cast<std::size_t>(c)]);
      double sum = col(0) * x(0);
      for (Index k = 1; k < n_; ++k) sum += col(k) * x(k);
      r(c) = (0.0 + sum) + b_(clamped_[static_cast<std::size_t>(c)]);
    }
    factor_.solveInPlace(r);
    for (Index c = 0; c < m; ++c) x(clamped_[static_cast<std::size_t>(c)]) -= r(c);
  }

  PassStatus drive(int d, int& pivots) {
    VectorXd& w = w_;
    VectorXd& dw = dw_;
    residualVelocity(a_, b_, x, w);
    for (;;) {
      if (++pivots > pb_.max_pivots) return PassStatus::Failed;
      if (w(d) == 0 && lo(d) < x(d) && x(d) < hi(d)) return addToClamped(d) ? PassStatus::Ok : PassStatus::Singular;
      const double dir = w(d) > 0 ? -1.0 : 1.0;

      auto dxc = dxc_.head(static_cast<Index>(clamped_.size()));
      for (Index c = 0; c < dxc.size(); ++c) dxc(c) = a_(clamped_[static_cast<std::size_t>(c)], d);
      factor_.solveInPlace(dxc);
      dxc *= -dir;
      dw = dir * a_.col(d);
      for (std::size_t c = 0; c < clamped_.size(); ++c) dw += a_.col(clamped_[c]) * dxc(static_cast<Index>(c));

      double t = kInfD;
      Event ev = Event::None;
      Index who = -1;
      if (dw(d) * w(d) < 0) {
        t = -w(d) / dw(d);
        ev = Event::DriveToC;
      }
      if (dir > 0 && hi(d) < kInfD && hi(d) - x(d) < t) {
        t = hi(d) - x(d);
        ev = Event::DriveToHi;
      }
      if (dir < 0 && lo(d) > -kInfD && x(d) - lo(d) < t) {
        t = x(d) - lo(d);
        ev = Event::DriveToLo;
      }
      for (std::size_t c = 0; c < clamped_.size(); ++c) {
        const int j = clamped_[c];
        const double dx = dxc(static_cast<Index>(c));
        if (dx < -kTinyStep && lo(j) > -kInfD) {
          const double t2 = (lo(j) - x(j)) / dx;
          if (t2 < t) {
            t = t2;
            ev = Event::ClampedToLo;
            who = static_cast<Index>(c);
          }
        } else if (dx > kTinyStep && hi(j) < kInfD) {
          const double t2 = (hi(j) - x(j)) / dx;
          if (t2 < t) {
            t = t2;
            ev = Event::ClampedToHi;
            who = static_cast<Index>(c);
          }
        }
      }
      for (Index j = 0; j < n_; ++j) {
        const RowState s = state_[static_cast<std::size_t>(j)];
        if (s != RowState::AtLo && s != RowState::AtHi) continue;
        if (lo(j) == hi(j)) continue;  // a zero-width box never needs w_j = 0 (ODE's rule)
        const bool leaves = s == RowState::AtLo ? dw(j) < -pb_.tiny_dw : dw(j) > pb_.tiny_dw;
        if (!leaves) continue;
        const double t2 = -w(j) / dw(j);
        if (t2 < t) {
          t = t2;
          ev = Event::BoundToC;
          who = j;
        }
      }

      if (ev == Event::None) {
        // Nothing stops the drive: x_d can move forever without w_d
        // changing sign, i.e. its Schur complement is not positive.
        return dir * dw(d) <= minPivot(d) + pb_.tiny_dw ? PassStatus::Singular : PassStatus::Failed;
      }
      t = std::max(t, 0.0);  // round-off can leave a row a hair past its bound
      for (Index c = 0; c < dxc.size(); ++c) x(clamped_[static_cast<std::size_t>(c)]) += t * dxc(c);
      x(d) += t * dir;
      w += t * dw;

      switch (ev) {
        case Event::DriveToC:
          if (!addToClamped(d)) return PassStatus::Singular;
          refineClamped();
          return PassStatus::Ok;
        case Event::DriveToLo:
          x(d) = lo(d);
          state_[static_cast<std::size_t>(d)] = RowState::AtLo;
          refineClamped();
          return PassStatus::Ok;
        case Event::DriveToHi:
          x(d) = hi(d);
          state_[static_cast<std::size_t>(d)] = RowState::AtHi;
          refineClamped();
          return PassStatus::Ok;
        case Event::ClampedToLo:
        case Event::ClampedToHi: {
          const int j = clamped_[static_cast<std::size_t>(who)];
          const bool to_lo = ev == Event::ClampedToLo;
          x(j) = to_lo ? lo(j) : hi(j);
          state_[static_cast<std::size_t>(j)] = to_lo ? RowState::AtLo : RowState::AtHi;
          factor_.remove(who);
          clamped_.erase(clamped_.begin() + who);
          break;
        }
        case Event::BoundToC:
          if (!addToClamped(static_cast<int>(who))) return PassStatus::Singular;
          w(who) = 0;
          break;
        case Event::None:
          break;
      }
      // Keep w exact between pivots of a long drive.
      refineClamped();
      residualVelocity(a_, b_, x, w);
    }
  }

  const Problem& pb_;
  const MatrixXd& a_;
  const VectorXd& b_;
  Index n_;
  ClampedFactor& factor_;
  std::vector<RowState>& state_;
  std::vector<int>& clamped_;
  std::vector<int>& refactor_;
  VectorXd &col_, &r_, &w_, &dw_, &dxc_;
};

// Everything a solve needs beyond its input, kept between solves: after
// the first solves of a size, the step's exact solve allocates nothing.
struct LcpWorkspace {
  DenseLcp lcp;          // solveLcpExact's assembled problem
  Problem pb, truth;     // the problem as pivoted, and as reported
  PassScratch pass;
  VectorXd w;            // A x + b, for the residual and the natural map's sets
  VectorXd best, prev, cur, next;
  MatrixXd a_reg;        // A + r I after a singular restart
  MatrixXd m;            // the Newton step's system
  VectorXd q;
  Eigen::PartialPivLU<MatrixXd> lu;
  std::vector<RowState> sets, next_sets;
  std::vector<int> normal;  // solveDense's friction rows
  VectorXd mu, lo, hi;      // solveDense's coefficients and bounds
};

// max_i |F_i| of the natural map with w = A x + b and the friction bounds
// implied by x itself (the coupled problem's residual).
double coupledResidual(const MatrixXd& a, const VectorXd& b, const VectorXd& x, const Problem& pb, VectorXd& w) {
  residualVelocity(a, b, x, w);
  double res = 0;
  for (Index i = 0; i < x.size(); ++i) {
    double lo = pb.lo(i), hi = pb.hi(i);
    const int nr = pb.normal[static_cast<std::size_t>(i)];
    if (nr >= 0) {
      hi = std::abs(pb.mu(i) * x(nr));
      lo = -hi;
    }
    res = std::max(res, std::abs(naturalMap(x(i), w(i), lo, hi)));
  }
  return res;
}

// Largest |bound used - bound implied by x| over the friction rows.
double frictionBoundChange(const DantzigPass& pass, const Problem& pb) {
  double change = 0;
  for (Index i = 0; i < pass.x.size(); ++i) {
    const int nr = pb.normal[static_cast<std::size_t>(i)];
    if (nr < 0) continue;
    change = std::max(change, std::abs(pass.hi(i) - std::abs(pb.mu(i) * pass.x(nr))));
  }
  return change;
}

// Newton's step on the piecewise-linear natural map: with the index sets
// held fixed, the coupled LCP is linear:
//   clamped row:            (A x + b)_i = 0
//   row at a fixed bound:   x_i = lo_i or hi_i
//   friction at a bound:    x_i = -+ mu_i sgn(mu_i x_n) x_n   (n its normal)
// Solved with a pivoted LU (the friction rows make it unsymmetric). `x`
// gives the signs of the normal impulses; the answer goes to ws.next.
bool solveActiveSet(const MatrixXd& a, const VectorXd& b, const std::vector<RowState>& sets, const VectorXd& x,
                    const Problem& pb, LcpWorkspace& ws) {
  const Index n = b.size();
  MatrixXd& m = ws.m;
  VectorXd& q = ws.q;
  m.setZero(n, n);
  q.setZero(n);
  for (Index i = 0; i < n; ++i) {
    const RowState st = sets[static_cast<std::size_t>(i)];
    if (st == RowState::Clamped) {
      m.row(i) = a.row(i);
      q(i) = -b(i);
      continue;
    }
    m(i, i) = 1;
    const int nr = pb.normal[static_cast<std::size_t>(i)];
    if (st == RowState::Free) {
      q(i) = x(i);
    } else if (nr < 0) {
      q(i) = st == RowState::AtLo ? pb.lo(i) : pb.hi(i);
    } else {
      const double sign = pb.mu(i) * x(nr) >= 0 ? 1.0 : -1.0;
      m(i, nr) -= (st == RowState::AtHi ? 1.0 : -1.0) * sign * pb.mu(i);
    }
  }
  ws.lu.compute(m);
  ws.next = ws.lu.solve(q);
  return ws.next.allFinite();
}

// The index sets the natural map selects at x: the branch of
// clamp(x_i - w_i, lo_i, hi_i) each row is on (bounds coupled to x).
void naturalMapSets(const MatrixXd& a, const VectorXd& b, const VectorXd& x, const Problem& pb, VectorXd& w,
                    std::vector<RowState>& sets) {
  residualVelocity(a, b, x, w);
  sets.resize(static_cast<std::size_t>(x.size()));
  for (Index i = 0; i < x.size(); ++i) {
    double lo = pb.lo(i), hi = pb.hi(i);
    const int nr = pb.normal[static_cast<std::size_t>(i)];
    if (nr >= 0) {
      hi = std::abs(pb.mu(i) * x(nr));
      lo = -hi;
    }
    const double z = x(i) - w(i);
    sets[static_cast<std::size_t>(i)] = z <= lo ? RowState::AtLo : (z >= hi ? RowState::AtHi : RowState::Clamped);
  }
}

// The answer in ws.best (size n).
void solveCore(const MatrixXd& a, const VectorXd& b, const VectorXd& lo, const VectorXd& hi,
               const std::vector<int>& normal_in, const VectorXd& mu, const ExactLcpOptions& opt,
               ExactLcpResult& res, LcpWorkspace& ws) {
  const Index n = b.size();
  res = ExactLcpResult{};
  VectorXd& best = ws.best;
  if (n == 0) {
    res.converged = true;
    best.resize(0);
    return;
  }

  Problem& pb = ws.pb;
  pb.A = nullptr;
  pb.b = &b;
  pb.lo = lo;
  pb.hi = hi;
  pb.mu = mu;
  pb.normal.assign(static_cast<std::size_t>(n), -1);
  pb.order.clear();
  pb.num_unbounded = 0;
  for (Index i = 0; i < n; ++i) {
    const int nr = normal_in.empty() ? -1 : normal_in[static_cast<std::size_t>(i)];
    if (nr >= 0 && nr < n && nr != i) {
      pb.normal[static_cast<std::size_t>(i)] = nr;
    } else if (pb.lo(i) > pb.hi(i)) {
      pb.hi(i) = pb.lo(i);  // an empty box: treat as lambda fixed at lo
    }
  }
  // The reported residual uses these bounds; the pivoting may pin rows.
  ws.truth = pb;
  // An inert row (zero row and column of A: it moves no body and has no
  // cfm) cannot change any w, not even its own: pin its lambda at
  // clamp(0, lo, hi) instead of letting it make A singular.
  bool has_friction = false;
  for (Index i = 0; i < n; ++i) {
    if (a.col(i).isZero(0)) {
      const bool friction = pb.normal[static_cast<std::size_t>(i)] >= 0;
      const double v = friction ? 0.0 : std::clamp(0.0, pb.lo(i), pb.hi(i));
      pb.normal[static_cast<std::size_t>(i)] = -1;
      pb.lo(i) = pb.hi(i) = v;
    }
    has_friction = has_friction || pb.normal[static_cast<std::size_t>(i)] >= 0;
  }
  for (int pass = 0; pass < 3; ++pass) {
    for (Index i = 0; i < n; ++i) {
      const bool friction = pb.normal[static_cast<std::size_t>(i)] >= 0;
      const bool unbounded = !friction && pb.lo(i) == -kInfD && pb.hi(i) == kInfD;
      const int group = unbounded ? 0 : (friction ? 2 : 1);
      if (group == pass) pb.order.push_back(static_cast<int>(i));
      if (pass == 0 && unbounded) ++pb.num_unbounded;
    }
  }
  const double max_diag = std::max(a.diagonal().maxCoeff(), 0.0);
  const double scale = max_diag > 0 ? max_diag : 1.0;
  pb.tiny_dw = kTinyStep * scale;
  pb.max_pivots = opt.max_pivots > 0 ? opt.max_pivots : static_cast<int>(20 * n + 100);
  const int max_passes = has_friction ? std::max(1, opt.max_friction_iterations) : 1;

  bool have_best = false;
  double best_res = kInfD;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (attempt == 1) {
      res.regularized = true;
      res.regularization = opt.regularization * scale;
      ws.a_reg = a;
      ws.a_reg.diagonal().array() += res.regularization;
    }
    pb.A = attempt == 0 ? &a : &ws.a_reg;
    pb.singular_pivot = attempt == 0 ? opt.singular_pivot : 0.0;

    DantzigPass pass(pb, ws.pass);
    VectorXd& prev = ws.prev;
    bool have_prev = false;
    bool singular = false;
    res.converged = false;
    res.friction_iterations = 0;
    have_best = false;
    best_res = kInfD;
    // Keeps the candidate with the smallest residual of the problem being
    // solved: the regularized matrix after a restart, inert rows pinned
    // (an inert row's w may be unsatisfiable; that is not the solver's
    // error and must not block convergence of the others).
    auto consider = [&](const VectorXd& x) {
      const double r = coupledResidual(*pb.A, b, x, pb, ws.w);
      if (r < best_res) {
        best = x;
        have_best = true;
        best_res = r;
      }
      return r;
    };
    double x_scale = 0;
    for (int k = 0; k < max_passes; ++k) {
      ++res.friction_iterations;
      int pass_pivots = 0;
      const PassStatus st = pass.run(have_prev ? &prev : nullptr, pass_pivots);
      res.pivots += pass_pivots;
      if (st == PassStatus::Singular) {
        singular = true;
        break;
      }
      if (st == PassStatus::Failed) {
        if (!have_best && pass.x.allFinite()) {
          ws.cur = pass.x.cwiseMax(pass.lo).cwiseMin(pass.hi);
          consider(ws.cur);
        }
        break;
      }
      consider(pass.x);
      if (!has_friction) {
        res.converged = true;
        break;
      }
      // Tolerances scale with the first (ODE) pass's impulses, fixed for the
      // solve: a diverging iteration (friction pumping its own normal, as
      // when mu |dlambda_n / dlambda_f| > 1) must not loosen them.
      if (k == 0) x_scale = pass.x.lpNorm<Eigen::Infinity>();
      if (frictionBoundChange(pass, pb) <= opt.tolerance * x_scale) {
        best = pass.x;  // the bounds it was solved with are its own: exact
        have_best = true;
        res.converged = true;
        break;
      }
      // The pass's index sets, with each sliding friction impulse tied to
      // its normal, make one linear system whose solution is exact when
      // those sets are the coupled problem's.
      if (opt.polish_active_set) {
        std::vector<RowState>& sets = ws.sets;
        sets.resize(static_cast<std::size_t>(n));
        for (Index i = 0; i < n; ++i) sets[static_cast<std::size_t>(i)] = pass.state(i);
        // Not the candidate's own scale either: a nearly singular Newton
        // system can return huge impulses whose residual is small only
        // relative to themselves. F mixes impulse and velocity entries.
        const double f_scale = std::max({b.lpNorm<Eigen::Infinity>(), max_diag * x_scale, x_scale});
        VectorXd& cur = ws.cur;
        cur = pass.x;
        for (int it = 0; it < kNewtonSteps && solveActiveSet(*pb.A, b, sets, cur, pb, ws); ++it) {
          cur = ws.next;
          const double r = consider(cur);
          if (r <= opt.tolerance * f_scale) {
            best = cur;
            have_best = true;
            res.converged = true;
            break;
          }
          naturalMapSets(*pb.A, b, cur, pb, ws.w, ws.next_sets);
          if (ws.next_sets == sets) break;  // Newton stalled on this piece
          std::swap(sets, ws.next_sets);
        }
        if (res.converged) break;
      }
      // Next bound source: the average of this one and the pass's answer.
      // The plain iteration x -> pass(bounds(x)) oscillates when friction
      // strongly changes the normals (large mu, lever arms); averaging
      // (Krasnoselskii-Mann) damps that and keeps the same fixed points.
      if (have_prev) {
        prev = 0.5 * (prev + pass.x);
      } else {
        prev = pass.x;
        have_prev = true;
      }
    }
    if (!singular || attempt == 1) break;
  }
  if (!have_best || !best.allFinite()) {
    best.setZero(n);
    res.converged = false;
  }
  res.residual = coupledResidual(a, b, best, ws.truth, ws.w);
}

}  // namespace

struct ExactLcpSolver::Impl {
  LcpWorkspace ws;
};

ExactLcpSolver::ExactLcpSolver() : impl_(std::make_unique<Impl>()) {}
ExactLcpSolver::~ExactLcpSolver() = default;
ExactLcpSolver::ExactLcpSolver(ExactLcpSolver&&) noexcept = default;
ExactLcpSolver& ExactLcpSolver::operator=(ExactLcpSolver&&) noexcept = default;

ExactLcpResult ExactLcpSolver::solve(std::span<ConstraintRow> rows, std::span<SolverBody> bodies,
                                     const ExactLcpOptions& options) {
  LcpWorkspace& ws = impl_->ws;
  if (options.velocities_include_lambda) {
    for (const ConstraintRow& r : rows) {
      if (std::isfinite(r.lambda)) applyRowImpulse(r, -r.lambda, bodies);
    }
  }
  DenseLcp& lcp = ws.lcp;
  assembleDenseLcp(rows, bodies, lcp);
  ExactLcpResult res;
  solveCore(lcp.A, lcp.b, lcp.lo, lcp.hi, lcp.normal_row, lcp.mu, options, res, ws);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].lambda = ws.best(static_cast<Index>(i));
    applyRowImpulse(rows[i], rows[i].lambda, bodies);
  }
  res.residual = lcpResidual(rows, bodies, ResidualNorm::Max);
  return res;
}

const Eigen::VectorXd& ExactLcpSolver::solveDense(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                                                  const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                                                  std::span<const int> findex, const ExactLcpOptions& options,
                                                  ExactLcpResult* result) {
  LcpWorkspace& ws = impl_->ws;
  const Index n = b.size();
  ws.normal.assign(static_cast<std::size_t>(n), -1);
  ws.mu.setZero(n);
  ws.lo = lo;
  ws.hi = hi;
  for (Index i = 0; i < n && static_cast<std::size_t>(i) < findex.size(); ++i) {
    const int f = findex[static_cast<std::size_t>(i)];
    if (f < 0 || f >= n || f == i) continue;  // not a (valid) friction row: its own bounds
    ws.normal[static_cast<std::size_t>(i)] = f;
    ws.mu(i) = hi(i);  // ODE's convention: hi carries mu for friction rows
    ws.lo(i) = 0;
    ws.hi(i) = 0;
  }
  ExactLcpResult res;
  solveCore(A, b, ws.lo, ws.hi, ws.normal, ws.mu, options, res, ws);
  if (result != nullptr) *result = res;
  return ws.best;
}

ExactLcpResult solveLcpExact(std::span<ConstraintRow> rows, std::span<SolverBody> bodies,
                             const ExactLcpOptions& options) {
  return ExactLcpSolver().solve(rows, bodies, options);
}

Eigen::VectorXd solveLcpExactDense(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lo,
                                   const Eigen::VectorXd& hi, std::span<const int> findex,
                                   const ExactLcpOptions& options, ExactLcpResult* result) {
  ExactLcpSolver solver;
  return solver.solveDense(A, b, lo, hi, findex, options, result);
}

}  // namespace cairn
