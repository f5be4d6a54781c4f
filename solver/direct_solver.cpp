#include "solver/direct_solver.hpp"

#include "solver/dense_system.hpp"
#include "solver/lcp_residual.hpp"
#include "solver/tree_factor.hpp"

#include <Eigen/CholmodSupport>

#include <algorithm>
#include <cmath>

namespace cairn {

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// A factor whose smallest-to-largest pivot ratio is below this is treated
// as singular. CHOLMOD only reports "not positive definite" for a pivot
// <= 0; a linearly dependent row whose pivot round-off left at +1e-17
// would otherwise be solved with a 1e16 gain. Genuine pivots of joint
// systems stay many orders above this.
constexpr double kSingularPivotRatio = 1e-12;

bool isBilateral(const ConstraintRow& r, std::size_t i, std::size_t n) {
  const bool friction = r.normal_row >= 0 && static_cast<std::size_t>(r.normal_row) < n &&
                        static_cast<std::size_t>(r.normal_row) != i;
  return !friction && r.lo == -kInf && r.hi == kInf;
}


// FNV-1a over the structure key (its size included).
std::uint64_t hashKey(const std::vector<std::int32_t>& key) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&h](std::uint64_t v) {
    for (int k = 0; k < 8; ++k) {
      h ^= (v >> (8 * k)) & 0xff;
      h *= 0x100000001b3ull;
    }
  };
  mix(key.size());
  for (std::int32_t v : key) mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(v)));
  return h;
}

// Exposes CHOLMOD's pivot-ratio estimate, which Eigen's wrapper keeps
// behind its protected factor pointer.
class CholmodFactor : public Eigen::CholmodDecomposition<SpMat, Eigen::Lower> {
 public:
  CholmodFactor() { this->cholmod().print = 0; }  // report through info(), not stderr
  // min/max of diag(L) (squared for LL^T), or |D| for LDL^T; 0 if singular.
  double pivotRatio() {
    return this->m_cholmodFactor != nullptr ? cholmod_rcond(this->m_cholmodFactor, &this->cholmod()) : 0.0;
  }
};

}  // namespace

struct DirectSolver::Impl {
  CholmodFactor factor;
  TreeFactor tree;  // used instead of CHOLMOD while the bilateral rows' bodies form a forest
  bool analysed = false;
  bool cholmod_analysed = false;  // CHOLMOD's symbolic analysis is of the current pattern
  std::vector<std::int32_t> key, next_key;  // coupling bodies of the bilateral rows, in order
  std::uint64_t hash = 0;
  int analysis_count = 0;
  // Scratch kept between calls so a steady scene does not allocate.
  std::vector<int> bilateral, unilateral;
  std::vector<Real> diag;
  std::vector<std::int32_t> coupling;  // per row: its coupling bodies (a, b), 0 for none
  Eigen::VectorXd rhs, delta;
  SparseAssembly assembly;
  SpMat abb;
};

DirectSolver::DirectSolver() : impl_(std::make_unique<Impl>()) {}
DirectSolver::~DirectSolver() = default;
DirectSolver::DirectSolver(DirectSolver&&) noexcept = default;
DirectSolver& DirectSolver::operator=(DirectSolver&&) noexcept = default;

int DirectSolver::analysisCount() const { return impl_->analysis_count; }
std::uint64_t DirectSolver::structureHash() const { return impl_->hash; }
void DirectSolver::reset() {
  impl_->analysed = false;
  impl_->key.clear();
  impl_->hash = 0;
}

DirectSolveStats DirectSolver::solve(std::span<ConstraintRow> rows, std::span<SolverBody> bodies,
                                     const DirectSolverOptions& opt) {
  Impl& s = *impl_;
  DirectSolveStats st;
  const std::size_t n = rows.size();

  // Starting impulse, and v = v* + M^-1 J^T lambda from here on; and the
  // partition, in the same walk over the rows (a chain's 300 rows are
  // 80 kB, past the first-level cache: each walk reads them again). Inert
  // rows keep lambda = clamp(0, lo, hi) and no velocity.
  s.bilateral.clear();
  s.unilateral.clear();
  s.diag.assign(n, 0);
  s.coupling.resize(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    ConstraintRow& r = rows[i];
    {
      const bool applied = opt.velocities_include_lambda;
      const Real start = opt.warm_start && std::isfinite(r.lambda) ? r.lambda : Real(0);
      const Real already = applied && std::isfinite(r.lambda) ? r.lambda : Real(0);
      applyRowImpulse(r, start - already, bodies);
      r.lambda = start;
    }
    const std::int32_t ca = couplingBodyA(r), cb = couplingBodyB(r);
    s.coupling[2 * i] = ca;
    s.coupling[2 * i + 1] = cb;
    s.diag[i] = rowSelfCoupling(r, ca, cb) + r.cfm;
    if (!(s.diag[i] > 0)) {
      // Inert: moves no body and has no cfm, so no lambda changes its w.
      const Real pinned = r.normal_row >= 0 ? Real(0) : std::clamp(Real(0), r.lo, std::max(r.lo, r.hi));
      applyRowImpulse(r, pinned - r.lambda, bodies);  // a no-op unless the row's blocks are inconsistent
      r.lambda = pinned;
      ++st.inert_rows;
      continue;
    }
    (isBilateral(r, i, n) ? s.bilateral : s.unilateral).push_back(static_cast<int>(i));
  }
  st.bilateral_rows = static_cast<int>(s.bilateral.size());
  st.unilateral_rows = static_cast<int>(s.unilateral.size());

  // Factor A_BB, reusing the analysis while the pattern is unchanged: the
  // tree factor when the rows' bodies form a forest (solver/tree_factor.hpp)
  // and A_BB is positive definite, else CHOLMOD. A singular A_BB (redundant
  // or conflicting rows) is regularised by CHOLMOD whatever the structure:
  // its shifted solve splits a dependent pair's impulse into huge opposite
  // halves whose round-off reaches the velocities, and the extremes suite's
  // redundant and conflicting joints are measured on that solve.
  bool have_factor = false;
  bool use_tree = false;
  if (!s.bilateral.empty()) {
    std::vector<std::int32_t>& key = s.next_key;
    key.clear();
    for (int i : s.bilateral) {
      key.push_back(s.coupling[2 * static_cast<std::size_t>(i)]);
      key.push_back(s.coupling[2 * static_cast<std::size_t>(i) + 1]);
    }
    if (!s.analysed || key != s.key) {
      s.analysed = true;
      s.cholmod_analysed = false;
      std::swap(s.key, key);
      s.hash = hashKey(s.key);
      ++s.analysis_count;
      st.analysed = true;
      s.tree.analyse(rows, s.bilateral);
    }
    st.structure_hash = s.hash;
    // CHOLMOD on one triangle, as the factor reads it (Eigen::Lower),
    // assembled into reused arrays; its symbolic analysis once per pattern.
    const auto cholmod = [&](double shift) {
      assembleSparseLower(rows, s.bilateral, CfmOnDiagonal::Include, s.assembly, s.abb);
      if (!s.cholmod_analysed) {
        s.factor.analyzePattern(s.abb);
        s.cholmod_analysed = true;
      }
      s.factor.setShift(shift);
      s.factor.factorize(s.abb);
      ++st.factorizations;
      return s.factor.info() == Eigen::Success;
    };
    if (s.tree.usable()) {
      ++st.factorizations;
      use_tree = s.tree.factorize(rows, s.bilateral, 0) && s.tree.pivotRatio() > kSingularPivotRatio;
      have_factor = use_tree;
    } else {
      have_factor = cholmod(0) && s.factor.pivotRatio() > kSingularPivotRatio;
    }
    if (!have_factor) {
      Real max_diag = 0;
      for (int i : s.bilateral) max_diag = std::max(max_diag, s.diag[static_cast<std::size_t>(i)]);
      st.regularized = true;
      st.regularization = opt.regularization * (max_diag > 0 ? max_diag : Real(1));
      have_factor = cholmod(st.regularization) && s.factor.pivotRatio() > 0;
      st.factorization_failed = !have_factor;
    }
    st.tree_factor = use_tree;
  }

  // (A_BB + C_B) delta = -w_B: the bilateral rows exactly, the others fixed.
  const auto nb = static_cast<Eigen::Index>(s.bilateral.size());
  auto solveBilateral = [&] {
    if (!have_factor) return;
    s.rhs.resize(nb);
    for (Eigen::Index p = 0; p < nb; ++p) {
      const ConstraintRow& r = rows[static_cast<std::size_t>(s.bilateral[static_cast<std::size_t>(p)])];
      s.rhs(p) = -(rowJv(r, bodies) - r.rhs + r.cfm * r.lambda);
    }
    bool solved = true;
    if (use_tree) {
      s.delta = s.rhs;
      s.tree.solveInPlace(std::span<double>(s.delta.data(), static_cast<std::size_t>(nb)));
    } else {
      s.delta = s.factor.solve(s.rhs);
      solved = s.factor.info() == Eigen::Success;
    }
    if (!solved || !s.delta.allFinite()) {
      st.factorization_failed = true;
      have_factor = false;
      return;
    }
    for (Eigen::Index p = 0; p < nb; ++p) {
      ConstraintRow& r = rows[static_cast<std::size_t>(s.bilateral[static_cast<std::size_t>(p)])];
      r.lambda += s.delta(p);
      applyRowImpulse(r, s.delta(p), bodies);
    }
  };

  const int outer = std::max(1, opt.outer_iterations);
  for (int k = 0; k < outer; ++k) {
    // 1. Bilateral rows exactly, the others fixed.
    solveBilateral();
    // 2. PGS on the unilateral rows, the bilateral ones fixed.
    for (int sweep = 0; sweep < opt.inner_pgs_iterations; ++sweep) {
      for (int i : s.unilateral) {
        ConstraintRow& r = rows[static_cast<std::size_t>(i)];
        const auto [lo, hi] = lcpRowBounds(rows, static_cast<std::size_t>(i));
        const Real w = rowJv(r, bodies) - r.rhs + r.cfm * r.lambda;
        const Real next = std::min(std::max(r.lambda - w / s.diag[static_cast<std::size_t>(i)], lo), hi);
        applyRowImpulse(r, next - r.lambda, bodies);
        r.lambda = next;
      }
    }
    ++st.outer_iterations;
    if (opt.report_residual) st.residual_history.push_back(lcpResidual(rows, bodies, ResidualNorm::Max));
    // Without unilateral rows one solve is exact, unless the shift made it
    // a proximal step that further solves refine.
    if (s.unilateral.empty() && !st.regularized) break;
  }
  // Finish on the bilateral rows, so joints hold exactly for the final
  // unilateral impulses (those keep the last PGS sweep's accuracy).
  if (!s.unilateral.empty()) solveBilateral();
  st.analysis_count = s.analysis_count;
  if (opt.report_residual) st.residual = lcpResidual(rows, bodies, ResidualNorm::Max);
  return st;
}

}  // namespace cairn
