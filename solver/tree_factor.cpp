#include "solver/tree_factor.hpp"

#include "solver/dense_system.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace cairn {

namespace {

// A body meeting d groups makes a clique of d blocks, and eliminating its
// groups costs about d^3 / 6 block updates. Past this many updates per
// group (a body with a few dozen joints) a general sparse factorization
// with its own ordering is the better tool.
constexpr std::size_t kUpdatesPerGroup = 8;

// The pair of bodies a row couples, as a group key: (0, 0) for a row that
// moves no body, (0, b) for a row moving one body b (a joint to the world,
// or both sides on b), (lo, hi) for two.
std::pair<std::int32_t, std::int32_t> pairKey(std::int32_t a, std::int32_t b) {
  if (a == b) b = 0;
  return {std::min(a, b), std::max(a, b)};
}

std::int32_t findRoot(std::vector<std::int32_t>& parent, std::int32_t x) {
  while (parent[static_cast<std::size_t>(x)] != x) {
    parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    x = parent[static_cast<std::size_t>(x)];
  }
  return x;
}

}  // namespace

bool TreeFactor::analyse(std::span<const ConstraintRow> rows, std::span<const int> subset) {
  usable_ = false;
  groups_.clear();
  pos_.clear();
  next_.clear();
  below_.clear();
  shared_.clear();
  update_.clear();
  const auto n = static_cast<std::int32_t>(subset.size());

  // Group the rows by body pair: sort positions by key, then by position.
  std::vector<std::pair<std::int32_t, std::int32_t>> key(static_cast<std::size_t>(n));
  std::int32_t max_body = 0;
  for (std::int32_t p = 0; p < n; ++p) {
    const ConstraintRow& r = rows[static_cast<std::size_t>(subset[static_cast<std::size_t>(p)])];
    key[static_cast<std::size_t>(p)] = pairKey(couplingBodyA(r), couplingBodyB(r));
    max_body = std::max(max_body, key[static_cast<std::size_t>(p)].second);
  }
  std::vector<std::int32_t> by_key(static_cast<std::size_t>(n));
  std::iota(by_key.begin(), by_key.end(), 0);
  std::stable_sort(by_key.begin(), by_key.end(),
                   [&](std::int32_t x, std::int32_t y) { return key[static_cast<std::size_t>(x)] < key[static_cast<std::size_t>(y)]; });
  struct Raw {
    std::int32_t lo, hi, first, size;  // bodies, first entry in by_key, rows
  };
  std::vector<Raw> raw;
  for (std::int32_t k = 0; k < n; ++k) {
    const auto [lo, hi] = key[static_cast<std::size_t>(by_key[static_cast<std::size_t>(k)])];
    if (raw.empty() || raw.back().lo != lo || raw.back().hi != hi) raw.push_back({lo, hi, k, 0});
    ++raw.back().size;
  }
  const auto groups = static_cast<std::int32_t>(raw.size());

  // Which groups meet each body; a cycle among the two-body groups means fill.
  std::vector<std::int32_t> uf(static_cast<std::size_t>(max_body) + 1);
  std::iota(uf.begin(), uf.end(), 0);
  std::vector<std::int32_t> degree(static_cast<std::size_t>(max_body) + 2, 0);
  for (const Raw& g : raw) {
    if (g.lo != 0) {
      const std::int32_t x = findRoot(uf, g.lo), y = findRoot(uf, g.hi);
      if (x == y) return false;
      uf[static_cast<std::size_t>(x)] = y;
      ++degree[static_cast<std::size_t>(g.lo) + 1];
    }
    if (g.hi != 0) ++degree[static_cast<std::size_t>(g.hi) + 1];
  }
  std::vector<std::int32_t> meet_start(degree.size(), 0);
  std::partial_sum(degree.begin(), degree.end(), meet_start.begin());
  std::vector<std::int32_t> meets(static_cast<std::size_t>(meet_start.back()));
  {
    std::vector<std::int32_t> fill(meet_start.begin(), meet_start.end() - 1);
    for (std::int32_t gi = 0; gi < groups; ++gi)
      for (const std::int32_t b : {raw[static_cast<std::size_t>(gi)].lo, raw[static_cast<std::size_t>(gi)].hi})
        if (b != 0) meets[static_cast<std::size_t>(fill[static_cast<std::size_t>(b)]++)] = gi;
  }

  // Elimination order, leaves first: at each body, the subtree of every
  // child body followed by the group joining it, then the groups hanging
  // off the body; its own parent group comes after, from its parent.
  std::vector<std::int32_t> order;  // raw group indices
  order.reserve(static_cast<std::size_t>(groups));
  std::vector<char> emitted(static_cast<std::size_t>(groups), 0), visited(static_cast<std::size_t>(max_body) + 1, 0);
  const auto emit = [&](std::int32_t gi) {
    if (!emitted[static_cast<std::size_t>(gi)]) order.push_back(gi);
    emitted[static_cast<std::size_t>(gi)] = 1;
  };
  for (std::int32_t gi = 0; gi < groups; ++gi)
    if (raw[static_cast<std::size_t>(gi)].hi == 0) emit(gi);  // moves no body: meets nothing
  struct Frame {
    std::int32_t body, via, next;  // via: the group from the parent (-1 at a root)
  };
  std::vector<Frame> stack;
  for (std::int32_t gi = 0; gi < groups; ++gi) {
    const std::int32_t root = raw[static_cast<std::size_t>(gi)].hi;
    if (root == 0 || visited[static_cast<std::size_t>(root)]) continue;
    visited[static_cast<std::size_t>(root)] = 1;
    stack.push_back({root, -1, meet_start[static_cast<std::size_t>(root)]});
    while (!stack.empty()) {
      Frame& f = stack.back();
      if (f.next < meet_start[static_cast<std::size_t>(f.body) + 1]) {
        const std::int32_t e = meets[static_cast<std::size_t>(f.next++)];
        const Raw& g = raw[static_cast<std::size_t>(e)];
        if (e == f.via || g.lo == 0) continue;  // the way up, or a group hanging off this body
        const std::int32_t child = g.lo == f.body ? g.hi : g.lo;
        visited[static_cast<std::size_t>(child)] = 1;
        stack.push_back({child, e, meet_start[static_cast<std::size_t>(child)]});
        continue;
      }
      const Frame done = f;
      stack.pop_back();
      for (std::int32_t k = meet_start[static_cast<std::size_t>(done.body)]; k < meet_start[static_cast<std::size_t>(done.body) + 1]; ++k)
        if (raw[static_cast<std::size_t>(meets[static_cast<std::size_t>(k)])].lo == 0) emit(meets[static_cast<std::size_t>(k)]);
      if (done.via >= 0) emit(done.via);
    }
  }
  std::vector<std::int32_t> rank(static_cast<std::size_t>(groups));
  for (std::int32_t e = 0; e < groups; ++e) rank[static_cast<std::size_t>(order[static_cast<std::size_t>(e)])] = e;

  // Groups, rows and the later neighbours of each group (the groups at
  // its bodies eliminated after it), with the blocks' offsets.
  groups_.resize(static_cast<std::size_t>(groups));
  std::int32_t offset = 0;
  for (std::int32_t e = 0; e < groups; ++e) {
    const Raw& g = raw[static_cast<std::size_t>(order[static_cast<std::size_t>(e)])];
    Group& out = groups_[static_cast<std::size_t>(e)];
    out.size = g.size;
    out.rows = static_cast<std::int32_t>(pos_.size());
    for (std::int32_t k = 0; k < g.size; ++k) pos_.push_back(by_key[static_cast<std::size_t>(g.first + k)]);
    out.body[0] = g.lo;
    out.body[1] = g.hi;
    if (g.size > kMaxGroupRows) return false;
    out.diag = offset;
    offset += g.size * g.size;
    out.next_begin = static_cast<std::int32_t>(next_.size());
    for (const std::int32_t b : {g.lo, g.hi}) {
      if (b == 0) continue;
      for (std::int32_t k = meet_start[static_cast<std::size_t>(b)]; k < meet_start[static_cast<std::size_t>(b) + 1]; ++k) {
        const std::int32_t other = rank[static_cast<std::size_t>(meets[static_cast<std::size_t>(k)])];
        if (other > e) next_.push_back(other);
      }
    }
    std::sort(next_.begin() + out.next_begin, next_.end());
    out.next_end = static_cast<std::int32_t>(next_.size());
    for (std::int32_t s = out.next_begin; s < out.next_end; ++s) {
      const Raw& k = raw[static_cast<std::size_t>(order[static_cast<std::size_t>(next_[static_cast<std::size_t>(s)])])];
      below_.push_back(offset);
      offset += k.size * g.size;
      // The body the two share, as a slot of each (0: lo, 1: hi).
      const std::int32_t body = (g.lo != 0 && (g.lo == k.lo || g.lo == k.hi)) ? g.lo : g.hi;
      shared_.push_back({body == g.lo ? 0 : 1, body == k.lo ? 0 : 1});
    }
  }
  values_.assign(static_cast<std::size_t>(offset), 0.0);

  // The Schur updates: every pair of a group's later neighbours must be
  // coupled already (no fill), else the ordering is not what it claims.
  for (std::int32_t e = 0; e < groups; ++e) {
    Group& g = groups_[static_cast<std::size_t>(e)];
    g.update_begin = static_cast<std::int32_t>(update_.size());
    for (std::int32_t si = g.next_begin; si < g.next_end; ++si)
      for (std::int32_t sk = si; sk < g.next_end; ++sk) {
        const std::int32_t i = next_[static_cast<std::size_t>(si)], k = next_[static_cast<std::size_t>(sk)];
        const Group& gi = groups_[static_cast<std::size_t>(i)];
        std::int32_t target = gi.diag;
        if (k != i) {
          const auto at = std::find(next_.begin() + gi.next_begin, next_.begin() + gi.next_end, k);
          if (at == next_.begin() + gi.next_end) return false;
          target = below_[static_cast<std::size_t>(at - next_.begin())];
        }
        update_.push_back({sk, si, target});
      }
    g.update_end = static_cast<std::int32_t>(update_.size());
    if (update_.size() > kUpdatesPerGroup * static_cast<std::size_t>(groups) + 64) return false;
  }
  work_.assign(static_cast<std::size_t>(n), 0.0);
  recip_.assign(static_cast<std::size_t>(n), 0.0);
  usable_ = true;
  return true;
}

namespace {

double dot6(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

// One group's rows gathered for one of its bodies: J's and M^-1 J^T's six
// entries per row (linear then angular), both sides summed when a row
// names the body twice.
template <int M, bool kWithMass>
void gatherSlot(std::span<const ConstraintRow> rows, std::span<const int> subset, const std::int32_t* pos, int m,
                std::int32_t body, double* j, double* mj) {
  const int size = M > 0 ? M : m;
  const auto put = [](double* out, const Vec3& lin, const Vec3& ang) {
    for (int c = 0; c < 3; ++c) {
      out[c] = lin[c];
      out[3 + c] = ang[c];
    }
  };
  for (int i = 0; i < size; ++i) {
    const ConstraintRow& r = rows[static_cast<std::size_t>(subset[static_cast<std::size_t>(pos[i])])];
    const bool a = r.body_a == body, b = r.body_b == body;
    if (a && b) {  // both sides on the body: their sum
      put(j + 6 * i, r.j_lin_a + r.j_lin_b, r.j_ang_a + r.j_ang_b);
      if constexpr (kWithMass) put(mj + 6 * i, r.m_lin_a + r.m_lin_b, r.m_ang_a + r.m_ang_b);
    } else if (a) {
      put(j + 6 * i, r.j_lin_a, r.j_ang_a);
      if constexpr (kWithMass) put(mj + 6 * i, r.m_lin_a, r.m_ang_a);
    } else {
      put(j + 6 * i, r.j_lin_b, r.j_ang_b);
      if constexpr (kWithMass) put(mj + 6 * i, r.m_lin_b, r.m_ang_b);
    }
  }
}

}  // namespace

// One group, eliminated: its blocks are assembled onto what the groups
// before it subtracted (A_gg's lower triangle, A_kg for each later
// neighbour k), then L_gg = chol(A_gg), L_kg = A_kg L_gg^-T, and the Schur
// updates A_ki -= L_kg L_ig^T among its later neighbours. M is the
// group's size when known at compile time (the loops over it unroll), 0
// for any other.
template <int M>
bool TreeFactor::eliminate(const Group& g, std::span<const ConstraintRow> rows, std::span<const int> subset,
                           double shift, double& lo, double& hi) {
  const int m = M > 0 ? M : g.size;
  const std::int32_t* pg = pos_.data() + g.rows;
  double base[2 * 12 * kMaxGroupRows];  // per body slot: J (m x 6), then M^-1 J^T (m x 6)
  for (int t = 0; t < 2; ++t)
    if (g.body[t] != 0)
      gatherSlot<M, true>(rows, subset, pg, m, g.body[t], base + t * 12 * m, base + t * 12 * m + 6 * m);

  double* l = values_.data() + g.diag;
  double* inv = recip_.data() + g.rows;  // 1 / L_jj: the triangular solves multiply
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j <= i; ++j) {
      double v = 0;
      for (int t = 0; t < 2; ++t)
        if (g.body[t] != 0) v += dot6(base + t * 12 * m + 6 * i, base + t * 12 * m + 6 * m + 6 * j);
      l[i * m + j] += v;
    }
    l[i * m + i] += rows[static_cast<std::size_t>(subset[static_cast<std::size_t>(pg[i])])].cfm + shift;
  }
  for (int j = 0; j < m; ++j) {
    double d = l[j * m + j];
    for (int k = 0; k < j; ++k) d -= l[j * m + k] * l[j * m + k];
    if (!(d > 0) || !std::isfinite(d)) return false;
    const double root = std::sqrt(d);
    l[j * m + j] = root;
    inv[j] = 1 / root;
    lo = std::min(lo, root);
    hi = std::max(hi, root);
    for (int i = j + 1; i < m; ++i) {
      double v = l[i * m + j];
      for (int k = 0; k < j; ++k) v -= l[i * m + k] * l[j * m + k];
      l[i * m + j] = v * inv[j];
    }
  }

  // L_kg = A_kg L_gg^-T for each later neighbour k; a neighbour of the
  // group's own size (a chain of like joints) with its loops unrolled.
  const auto below = [&]<int K>(const Group& k, const Shared& sh, double* b) {
    const int mk = K > 0 ? K : k.size;
    // k's J for the shared body (k's own elimination gathers its rows
    // again with the rest).
    double jk[6 * kMaxGroupRows];
    gatherSlot<K, false>(rows, subset, pos_.data() + k.rows, mk, k.body[sh.slot_k], jk, nullptr);
    const double* mg = base + sh.slot_g * 12 * m + 6 * m;
    for (int r = 0; r < mk; ++r)
      for (int j = 0; j < m; ++j) {
        double v = b[r * m + j] + dot6(jk + 6 * r, mg + 6 * j);
        for (int c = 0; c < j; ++c) v -= b[r * m + c] * l[j * m + c];
        b[r * m + j] = v * inv[j];
      }
  };
  for (std::int32_t s = g.next_begin; s < g.next_end; ++s) {
    const Group& k = groups_[static_cast<std::size_t>(next_[static_cast<std::size_t>(s)])];
    const Shared& sh = shared_[static_cast<std::size_t>(s)];
    double* b = values_.data() + below_[static_cast<std::size_t>(s)];
    if (M > 0 && k.size == M) below.template operator()<M>(k, sh, b);
    else below.template operator()<0>(k, sh, b);
  }
  // The Schur updates A_ki -= L_kg L_ig^T, unrolled where both neighbours
  // are of the group's size.
  const auto update = [&]<int K>(const Update& up, int mk, int mi) {
    if constexpr (K > 0) mk = mi = K;
    const double* bk = values_.data() + below_[static_cast<std::size_t>(up.k)];
    const double* bi = values_.data() + below_[static_cast<std::size_t>(up.i)];
    double* t = values_.data() + up.target;
    for (int r = 0; r < mk; ++r)
      for (int c = 0; c < mi; ++c) {
        double v = 0;
        for (int j = 0; j < m; ++j) v += bk[r * m + j] * bi[c * m + j];
        t[r * mi + c] -= v;
      }
  };
  for (std::int32_t u = g.update_begin; u < g.update_end; ++u) {
    const Update& up = update_[static_cast<std::size_t>(u)];
    const std::int32_t mk = groups_[static_cast<std::size_t>(next_[static_cast<std::size_t>(up.k)])].size;
    const std::int32_t mi = groups_[static_cast<std::size_t>(next_[static_cast<std::size_t>(up.i)])].size;
    if (M > 0 && mk == M && mi == M) update.template operator()<M>(up, mk, mi);
    else update.template operator()<0>(up, mk, mi);
  }
  return true;
}

bool TreeFactor::factorize(std::span<const ConstraintRow> rows, std::span<const int> subset, double shift) {
  pivot_ratio_ = 0;
  if (!usable_) return false;
  std::fill(values_.begin(), values_.end(), 0.0);
  double lo = INFINITY, hi = 0;
  for (const Group& g : groups_) {
    bool ok;
    switch (g.size) {  // the joints' common sizes: a ball 3, a hinge 5, a fixed joint 6
      case 1: ok = eliminate<1>(g, rows, subset, shift, lo, hi); break;
      case 2: ok = eliminate<2>(g, rows, subset, shift, lo, hi); break;
      case 3: ok = eliminate<3>(g, rows, subset, shift, lo, hi); break;
      case 4: ok = eliminate<4>(g, rows, subset, shift, lo, hi); break;
      case 5: ok = eliminate<5>(g, rows, subset, shift, lo, hi); break;
      case 6: ok = eliminate<6>(g, rows, subset, shift, lo, hi); break;
      default: ok = eliminate<0>(g, rows, subset, shift, lo, hi); break;
    }
    if (!ok) return false;
  }
  pivot_ratio_ = hi > 0 ? (lo / hi) * (lo / hi) : 0;
  return true;
}

template <int M>
void TreeFactor::forwardGroup(const Group& g, double* w) const {
  const std::int32_t m = M > 0 ? M : g.size;
  const double* l = values_.data() + g.diag;
  const double* inv = recip_.data() + g.rows;
  double* y = w + g.rows;
  for (std::int32_t j = 0; j < m; ++j) {
    double v = y[j];
    for (std::int32_t k = 0; k < j; ++k) v -= l[j * m + k] * y[k];
    y[j] = v * inv[j];
  }
  for (std::int32_t s = g.next_begin; s < g.next_end; ++s) {
    const Group& k = groups_[static_cast<std::size_t>(next_[static_cast<std::size_t>(s)])];
    const double* b = values_.data() + below_[static_cast<std::size_t>(s)];
    double* yk = w + k.rows;
    for (std::int32_t r = 0; r < k.size; ++r) {
      double v = 0;
      for (std::int32_t j = 0; j < m; ++j) v += b[r * m + j] * y[j];
      yk[r] -= v;
    }
  }
}

template <int M>
void TreeFactor::backwardGroup(const Group& g, double* w) const {
  const std::int32_t m = M > 0 ? M : g.size;
  const double* l = values_.data() + g.diag;
  const double* inv = recip_.data() + g.rows;
  double* y = w + g.rows;
  for (std::int32_t s = g.next_begin; s < g.next_end; ++s) {
    const Group& k = groups_[static_cast<std::size_t>(next_[static_cast<std::size_t>(s)])];
    const double* b = values_.data() + below_[static_cast<std::size_t>(s)];
    const double* xk = w + k.rows;
    for (std::int32_t j = 0; j < m; ++j) {
      double v = 0;
      for (std::int32_t r = 0; r < k.size; ++r) v += b[r * m + j] * xk[r];
      y[j] -= v;
    }
  }
  for (std::int32_t j = m - 1; j >= 0; --j) {
    double v = y[j];
    for (std::int32_t k = j + 1; k < m; ++k) v -= l[k * m + j] * y[k];
    y[j] = v * inv[j];
  }
}

// The sizes factorize's eliminate unrolls (the joints' common ones: a
// ball 3, a hinge 5, a fixed joint 6); the arithmetic, and its order, is
// the same for every size.
#define CAIRN_TREE_BY_SIZE(call)       \
  switch (g.size) {                   \
    case 1: call<1>(g, w); break;     \
    case 2: call<2>(g, w); break;     \
    case 3: call<3>(g, w); break;     \
    case 4: call<4>(g, w); break;     \
    case 5: call<5>(g, w); break;     \
    case 6: call<6>(g, w); break;     \
    default: call<0>(g, w); break;    \
  }

void TreeFactor::solveInPlace(std::span<double> x) const {
  double* w = work_.data();
  for (std::size_t k = 0; k < pos_.size(); ++k) w[k] = x[static_cast<std::size_t>(pos_[k])];
  // L y = x, group after group.
  for (const Group& g : groups_) CAIRN_TREE_BY_SIZE(forwardGroup)
  // L^T x = y, in reverse.
  for (auto it = groups_.rbegin(); it != groups_.rend(); ++it) {
    const Group& g = *it;
    CAIRN_TREE_BY_SIZE(backwardGroup)
  }
  for (std::size_t k = 0; k < pos_.size(); ++k) x[static_cast<std::size_t>(pos_[k])] = w[k];
}

#undef CAIRN_TREE_BY_SIZE

}  // namespace cairn
