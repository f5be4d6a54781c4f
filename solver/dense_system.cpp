#include "solver/dense_system.hpp"

#include <algorithm>
#include <cstddef>
#include <type_traits>

namespace cairn {

namespace {

// One row side that moves a body: which row (position in the assembled
// matrix) and which side, so its J and M^-1 J^T blocks can be read back.
struct SideRef {
  int pos;
  const ConstraintRow* row;
  bool side_b;
};

const Vec3& jLin(const SideRef& s) { return s.side_b ? s.row->j_lin_b : s.row->j_lin_a; }
const Vec3& jAng(const SideRef& s) { return s.side_b ? s.row->j_ang_b : s.row->j_ang_a; }
const Vec3& mLin(const SideRef& s) { return s.side_b ? s.row->m_lin_b : s.row->m_lin_a; }
const Vec3& mAng(const SideRef& s) { return s.side_b ? s.row->m_ang_b : s.row->m_ang_a; }

Real sideProduct(const SideRef& i, const SideRef& j) { return jLin(i).dot(mLin(j)) + jAng(i).dot(mAng(j)); }

}  // namespace

Real rowCoupling(const ConstraintRow& ri, const ConstraintRow& rj) {
  const std::int32_t bi[2] = {couplingBodyA(ri), couplingBodyB(ri)};
  const std::int32_t bj[2] = {couplingBodyA(rj), couplingBodyB(rj)};
  Real s = 0;
  for (int p = 0; p < 2; ++p) {
    if (bi[p] == 0) continue;
    const SideRef si{0, &ri, p == 1};
    for (int q = 0; q < 2; ++q) {
      if (bj[q] != bi[p]) continue;
      s += sideProduct(si, SideRef{0, &rj, q == 1});
    }
  }
  return s;
}

void assembleSparseLower(std::span<const ConstraintRow> rows, std::span<const int> subset, CfmOnDiagonal cfm,
                         SparseAssembly& s, Eigen::SparseMatrix<double>& out) {
  const int n = static_cast<int>(subset.size());
  s.pos_of_row.assign(rows.size(), -1);
  for (int k = 0; k < n; ++k) s.pos_of_row[static_cast<std::size_t>(subset[static_cast<std::size_t>(k)])] = k;
  // Sides bucketed by body in row order (a counting sort: one pass to
  // count, one to place), so that only rows sharing a body are ever paired.
  std::int32_t max_body = 0;
  for (const ConstraintRow& r : rows) max_body = std::max({max_body, r.body_a, r.body_b});
  s.bucket_start.assign(static_cast<std::size_t>(max_body) + 2, 0);
  const auto forEachSide = [&](auto&& f) {
    for (std::size_t r = 0; r < rows.size(); ++r) {
      if (s.pos_of_row[r] < 0) continue;
      if (const std::int32_t k = couplingBodyA(rows[r]); k != 0) f(k, static_cast<int>(r), false);
      if (const std::int32_t k = couplingBodyB(rows[r]); k != 0) f(k, static_cast<int>(r), true);
    }
  };
  forEachSide([&](std::int32_t k, int, bool) { ++s.bucket_start[static_cast<std::size_t>(k) + 1]; });
  for (std::size_t k = 1; k < s.bucket_start.size(); ++k) s.bucket_start[k] += s.bucket_start[k - 1];
  s.sides.resize(static_cast<std::size_t>(s.bucket_start.back()));
  s.bucket_fill.assign(s.bucket_start.begin(), s.bucket_start.end() - 1);
  forEachSide([&](std::int32_t k, int r, bool b) {
    s.sides[static_cast<std::size_t>(s.bucket_fill[static_cast<std::size_t>(k)]++)] = {r, b};
  });
  const auto ref = [&](std::size_t p) {
    const auto [r, b] = s.sides[p];
    return SideRef{s.pos_of_row[static_cast<std::size_t>(r)], &rows[static_cast<std::size_t>(r)], b};
  };

  // Contributions (column = the smaller position), in a fixed order,
  // twice: once to count them per column (no values), once to place them.
  const auto contributions = [&](auto values, auto&& add) {
    constexpr bool kValues = decltype(values)::value;
    const auto product = [&](const SideRef& a, const SideRef& b) { return kValues ? sideProduct(a, b) : 0.0; };
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const int pos = s.pos_of_row[r];
      if (pos >= 0) add(pos, pos, cfm == CfmOnDiagonal::Include ? rows[r].cfm : 0.0);
    }
    for (std::size_t k = 0; k + 1 < s.bucket_start.size(); ++k) {
      const auto begin = static_cast<std::size_t>(s.bucket_start[k]), end = static_cast<std::size_t>(s.bucket_start[k + 1]);
      for (std::size_t p = begin; p < end; ++p) {
        const SideRef sp = ref(p);
        add(sp.pos, sp.pos, product(sp, sp));
        for (std::size_t q = p + 1; q < end; ++q) {
          const SideRef sq = ref(q);
          if (sp.pos == sq.pos) add(sp.pos, sp.pos, product(sp, sq) + product(sq, sp));
          else add(std::max(sp.pos, sq.pos), std::min(sp.pos, sq.pos), product(sp, sq));
        }
      }
    }
  };
  s.column_start.assign(static_cast<std::size_t>(n) + 1, 0);
  contributions(std::false_type{}, [&](int, int col, double) { ++s.column_start[static_cast<std::size_t>(col) + 1]; });
  for (std::size_t c = 1; c < s.column_start.size(); ++c) s.column_start[c] += s.column_start[c - 1];
  s.entries.resize(static_cast<std::size_t>(s.column_start.back()));
  s.column_fill.assign(s.column_start.begin(), s.column_start.end() - 1);
  contributions(std::true_type{}, [&](int row, int col, double v) {
    s.entries[static_cast<std::size_t>(s.column_fill[static_cast<std::size_t>(col)]++)] = {row, v};
  });

  // Per column: rows ascending (a stable insertion sort keeps the order of
  // equal rows), duplicates summed in that order, compacted in place.
  int nnz = 0;
  for (int c = 0; c < n; ++c) {
    const int begin = s.column_start[static_cast<std::size_t>(c)], end = s.column_start[static_cast<std::size_t>(c) + 1];
    SparseAssembly::Entry* e = s.entries.data();
    for (int i = begin + 1; i < end; ++i) {
      const SparseAssembly::Entry x = e[i];
      int j = i;
      for (; j > begin && e[j - 1].row > x.row; --j) e[j] = e[j - 1];
      e[j] = x;
    }
    s.column_start[static_cast<std::size_t>(c)] = nnz;
    for (int i = begin; i < end; ++i) {
      if (i > begin && e[i].row == e[nnz - 1].row) e[nnz - 1].value += e[i].value;
      else e[nnz++] = e[i];
    }
  }
  s.column_start[static_cast<std::size_t>(n)] = nnz;
  out.resize(n, n);
  out.resizeNonZeros(nnz);
  std::copy(s.column_start.begin(), s.column_start.end(), out.outerIndexPtr());
  for (int i = 0; i < nnz; ++i) {
    out.innerIndexPtr()[i] = s.entries[static_cast<std::size_t>(i)].row;
    out.valuePtr()[i] = s.entries[static_cast<std::size_t>(i)].value;
  }
}

namespace {

// Into `a` and `b`, resized (their storage is kept when the size is).
void fillDenseA(std::span<const ConstraintRow> rows, CfmOnDiagonal cfm, Eigen::MatrixXd& a) {
  const auto n = static_cast<Eigen::Index>(rows.size());
  a.resize(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const ConstraintRow& ri = rows[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j <= i; ++j) {
      a(i, j) = a(j, i) = rowCoupling(ri, rows[static_cast<std::size_t>(j)]);
    }
    if (cfm == CfmOnDiagonal::Include) a(i, i) += ri.cfm;
  }
}

void fillB(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies, Eigen::VectorXd& b) {
  b.resize(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t i = 0; i < rows.size(); ++i) b(static_cast<Eigen::Index>(i)) = rowJv(rows[i], bodies) - rows[i].rhs;
}

}  // namespace

Eigen::MatrixXd assembleDenseA(std::span<const ConstraintRow> rows, CfmOnDiagonal cfm) {
  Eigen::MatrixXd a;
  fillDenseA(rows, cfm, a);
  return a;
}

Eigen::VectorXd assembleB(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies) {
  Eigen::VectorXd b;
  fillB(rows, bodies, b);
  return b;
}

Eigen::SparseMatrix<double> assembleSparseA(std::span<const ConstraintRow> rows, CfmOnDiagonal cfm) {
  std::vector<int> all(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) all[i] = static_cast<int>(i);
  return assembleSparseA(rows, all, cfm);
}

// Both triangles: the lower one mirrored, so A is exactly symmetric and
// keeps every stored entry (explicit zeros on the diagonal included).
Eigen::SparseMatrix<double> assembleSparseA(std::span<const ConstraintRow> rows, std::span<const int> subset,
                                           CfmOnDiagonal cfm) {
  SparseAssembly scratch;
  Eigen::SparseMatrix<double> lower;
  assembleSparseLower(rows, subset, cfm, scratch, lower);
  Eigen::SparseMatrix<double> full = lower.selfadjointView<Eigen::Lower>();
  full.makeCompressed();
  return full;
}

void assembleDenseLcp(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies, DenseLcp& lcp) {
  const auto n = static_cast<Eigen::Index>(rows.size());
  fillDenseA(rows, CfmOnDiagonal::Include, lcp.A);
  fillB(rows, bodies, lcp.b);
  lcp.lo.resize(n);
  lcp.hi.resize(n);
  lcp.mu.resize(n);
  lcp.normal_row.resize(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    lcp.lo(k) = rows[i].lo;
    lcp.hi(k) = rows[i].hi;
    lcp.mu(k) = rows[i].mu;
    lcp.normal_row[i] = rows[i].normal_row;
  }
}

DenseLcp assembleDenseLcp(std::span<const ConstraintRow> rows, std::span<const SolverBody> bodies) {
  DenseLcp lcp;
  assembleDenseLcp(rows, bodies, lcp);
  return lcp;
}

}  // namespace cairn
