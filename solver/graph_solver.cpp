#include "solver/graph_solver.hpp"

#include "solver/worker_pool.hpp"

#include <algorithm>
#include <cmath>

namespace cairn {

namespace {

// A sweep that moved no impulse by more than this fraction of the largest
// impulse has reached a fixed point to round-off (pgs.cpp, kRoundOff).
constexpr Real kRoundOff = Real(1e-13);

// splitmix64, as pgs.cpp: a fixed sequence for a seed on every platform.
std::uint64_t nextRandom(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

inline Real rowVelocity(const ConstraintRow& r, const SolverBody& a, const SolverBody& b) {
  return r.j_lin_a.dot(a.v) + r.j_ang_a.dot(a.w) + r.j_lin_b.dot(b.v) + r.j_ang_b.dot(b.w);
}

// Adds M^-1 J^T d to the row's bodies that may be written (pgs.cpp's
// applyImpulse, without touching the read-only bodies).
inline void applyRow(const ConstraintRow& r, std::span<SolverBody> bodies, int dynamic_end, Real d) {
  if (r.body_a > 0 && r.body_a < dynamic_end) {
    SolverBody& a = bodies[static_cast<size_t>(r.body_a)];
    a.v += r.m_lin_a * d;
    a.w += r.m_ang_a * d;
  }
  if (r.body_b > 0 && r.body_b < dynamic_end) {
    SolverBody& b = bodies[static_cast<size_t>(r.body_b)];
    b.v += r.m_lin_b * d;
    b.w += r.m_ang_b * d;
  }
}

inline void rowBounds(const ConstraintRow& r, const ConstraintRow* group_rows, Real& lo, Real& hi) {
  lo = r.lo;
  hi = r.hi;
  if (r.normal_row >= 0) {
    hi = r.mu * group_rows[r.normal_row].lambda;
    lo = -hi;
  }
}

inline bool active(const GraphProblem& p, std::int32_t island) { return p.island_active[static_cast<size_t>(island)] > 0; }

// One visit of a group: each row in order (pgs.cpp's solveRow).
void solveGroup(GraphProblem& p, std::int32_t gi, std::span<SolverBody> bodies, const GraphSolveOptions& o,
                bool gather_change) {
  const RowGroup& g = p.groups[static_cast<size_t>(gi)];
  if (!active(p, g.island)) return;
  ConstraintRow* rows = p.rows.data() + g.begin;
  Real max_delta = 0, max_lambda = 0;
  for (std::int32_t k = 0; k < g.end - g.begin; ++k) {
    ConstraintRow& r = rows[k];
    const SolverBody& a = bodies[static_cast<size_t>(r.body_a)];
    const SolverBody& b = bodies[static_cast<size_t>(r.body_b)];
    Real lo, hi;
    rowBounds(r, rows, lo, hi);
    const Real delta = (r.rhs - rowVelocity(r, a, b) - r.cfm * r.lambda) * r.inv_diag;
    const Real next = std::clamp(r.lambda + o.sor * delta, lo, hi);
    const Real d = next - r.lambda;
    r.lambda = next;
    applyRow(r, bodies, o.dynamic_end, d);
    max_delta = std::max(max_delta, std::abs(d));
    max_lambda = std::max(max_lambda, std::abs(next));
    if (gather_change) p.row_change[static_cast<size_t>(g.begin + k)] = d;
  }
  p.group_delta[static_cast<size_t>(gi)] = max_delta;
  p.group_lambda[static_cast<size_t>(gi)] = max_lambda;
}

void groupMomentum(GraphProblem& p, const RowGroup& g, std::span<SolverBody> bodies, int dynamic_end) {
  const double beta = p.island_beta[static_cast<size_t>(g.island)];
  if (beta < 0) return;  // the island has stopped
  ConstraintRow* rows = p.rows.data() + g.begin;
  for (std::int32_t k = 0; k < g.end - g.begin; ++k) {
    const size_t i = static_cast<size_t>(g.begin + k);
    if (beta == 0 || beta > 1) {  // first sweep: p = d; the sweeps stopped agreeing: restart, p = 0
      p.row_dir[i] = beta == 0 ? p.row_change[i] : Real(0);
      continue;
    }
    ConstraintRow& r = rows[k];
    Real lo, hi;
    rowBounds(r, rows, lo, hi);
    const Real next = std::clamp(r.lambda + beta * p.row_dir[i], lo, hi);
    const Real d = next - r.lambda;
    if (d != 0) {
      r.lambda = next;
      applyRow(r, bodies, dynamic_end, d);
    }
    p.row_dir[i] = beta * p.row_dir[i] + p.row_change[i];
  }
}

// Below this much work a loop runs on the calling thread. A batch visit
// (eight manifolds, one pass) is 0.5 to 1 us; handing a loop to the pool
// and meeting at its barrier costs about a microsecond. Measured on an idle
// machine with every colour handed over: a colour of one to three batches
// (pyramid-20's) or a lone joint (each colour of a chain) ran slower on
// two threads than on one (ragdoll 0.050 -> 0.084 ms/step, pyramid-20 0.40
// -> 0.43), while the 5,050-box pyramid, five batches a colour on average,
// gained 1.56x in its solve. Four batches, two per thread, is where the
// handover starts to pay. Work is counted in batch visits; a joint's row
// group is about an eighth of one.
constexpr double kParallelWork = 4;
constexpr double kGroupWork = 1.0 / 8;

// Runs fn(begin, end) over [0, count), on the pool's threads if there is one
// and the loop's `work` (in batch visits) pays for it.
template <class F>
void forRange(WorkerPool* pool, int count, double work, F&& fn) {
  if (count <= 0) return;
  if (pool && work >= kParallelWork) pool->parallelFor(count, fn);
  else fn(0, count);
}

ContactSweepParams sweepParams(const GraphProblem& p, const GraphSolveOptions& o, bool gather) {
  ContactSweepParams sp;
  sp.sor = o.sor;
  sp.dynamic_end = o.dynamic_end;
  sp.gather_change = gather;
  sp.friction_rows = o.friction_rows;
  sp.island_active = p.island_active.data();
  return sp;
}

// The items of a colour: its row groups, then its manifold batches. Every
// item writes only its own constraints' bodies, so any split of the items
// among threads gives the same result.
template <class Groups, class Batches>
void forColour(const GraphColour& c, WorkerPool* pool, Groups&& groups_fn, Batches&& batches_fn) {
  const int groups = c.group_end - c.group_begin, batches = c.batch_end - c.batch_begin;
  forRange(pool, groups + batches, batches + kGroupWork * groups, [&](int begin, int end) {
    for (int i = begin; i < std::min(end, groups); ++i) groups_fn(c.group_begin + i);
    const int b0 = std::max(begin, groups) - groups, b1 = end - groups;
    if (b1 > b0) batches_fn(c.batch_begin + b0, c.batch_begin + b1);
  });
}

// Each island's largest change and impulse of the sweep, gathered in
// storage order (the same whatever the threads did).
void reduceSweep(GraphProblem& p, bool contacts) {
  std::fill(p.island_delta.begin(), p.island_delta.end(), 0.0);
  std::fill(p.island_lambda.begin(), p.island_lambda.end(), 0.0);
  const auto fold = [&](std::int32_t island, double delta, double lambda) {
    const size_t i = static_cast<size_t>(island);
    // NaN must win: a non-finite island never looks converged.
    if (!(p.island_delta[i] >= delta)) p.island_delta[i] = delta;
    if (!(p.island_lambda[i] >= lambda)) p.island_lambda[i] = lambda;
  };
  if (contacts)
    for (const ContactBatch& b : p.batches)
      for (int l = 0; l < kBatchLanes; ++l)
        if (b.count[l] > 0 && active(p, b.island[l])) fold(b.island[l], b.sweep_delta[l], b.sweep_lambda[l]);
  for (size_t g = 0; g < p.groups.size(); ++g)
    if (active(p, p.groups[g].island)) fold(p.groups[g].island, p.group_delta[g], p.group_lambda[g]);
}

// Stops the islands that reached the tolerance or a round-off fixed point;
// returns whether any island goes on.
bool stopConverged(GraphProblem& p, const GraphSolveOptions& o, int sweeps) {
  bool any = false;
  for (size_t i = 0; i < p.island_active.size(); ++i) {
    if (p.island_active[i] == 0) continue;
    p.island_iterations[i] = sweeps;
    const double d = p.island_delta[i];
    if ((o.tolerance > 0 && d <= o.tolerance) || d <= kRoundOff * p.island_lambda[i]) p.island_active[i] = 0;
    else any = true;
  }
  return any;
}

// beta per island from this sweep's squared change (summed in storage
// order); -1 for islands that have stopped.
void islandBetas(GraphProblem& p) {
  std::fill(p.island_norm2.begin(), p.island_norm2.end(), 0.0);
  for (const ContactBatch& b : p.batches)
    for (int l = 0; l < kBatchLanes; ++l)
      if (b.count[l] > 0) p.island_norm2[static_cast<size_t>(b.island[l])] += b.change2[l];
  for (const RowGroup& g : p.groups)
    for (std::int32_t i = g.begin; i < g.end; ++i) {
      const Real d = p.row_change[static_cast<size_t>(i)];
      p.island_norm2[static_cast<size_t>(g.island)] += d * d;
    }
  for (size_t i = 0; i < p.island_norm2.size(); ++i) {
    if (p.island_active[i] == 0) {
      p.island_beta[i] = -1;
      continue;
    }
    const double prev = p.island_prev_norm2[i];
    p.island_beta[i] = prev > 0 ? p.island_norm2[i] / prev : 0.0;
    p.island_prev_norm2[i] = p.island_norm2[i];
  }
}

void orderColours(GraphProblem& p, bool randomize, std::uint64_t& rng_state) {
  const size_t n = p.colours.size();
  p.colour_order.resize(n);
  for (size_t i = 0; i < n; ++i) p.colour_order[i] = static_cast<std::int32_t>(i);
  if (randomize)
    for (size_t i = n; i > 1; --i) std::swap(p.colour_order[i - 1], p.colour_order[nextRandom(rng_state) % i]);
}

void startSweeps(GraphProblem& p) {
  const size_t n = static_cast<size_t>(p.island_count);
  p.island_active.assign(n, 1.0);
  p.island_delta.assign(n, 0.0);
  p.island_lambda.assign(n, 0.0);
  p.island_iterations.assign(n, 0);
  p.group_delta.assign(p.groups.size(), Real(0));
  p.group_lambda.assign(p.groups.size(), Real(0));
}

}  // namespace

GraphSolveStats solveGraph(GraphProblem& p, std::span<SolverBody> bodies, const GraphSolveOptions& o,
                           std::uint64_t& rng_state) {
  GraphSolveStats stats;
  if (p.empty()) return stats;
  double* body_data = bodies.front().v.data();
  startSweeps(p);

  // Warm start: the carried impulses act before the first sweep.
  const ContactSweepParams warm = sweepParams(p, o, false);
  for (const GraphColour& c : p.colours)
    forColour(
        c, o.pool,
        [&](std::int32_t gi) {
          const RowGroup& g = p.groups[static_cast<size_t>(gi)];
          for (std::int32_t k = g.begin; k < g.end; ++k) {
            const ConstraintRow& r = p.rows[static_cast<size_t>(k)];
            if (r.lambda != 0) applyRow(r, bodies, o.dynamic_end, r.lambda);
          }
        },
        [&](int b0, int b1) { o.kernels->warm_start(p.batches.data(), b0, b1, body_data, warm); });

  if (o.nncg) {
    p.row_change.assign(p.rows.size(), Real(0));
    p.row_dir.assign(p.rows.size(), Real(0));
    const size_t n = static_cast<size_t>(p.island_count);
    p.island_norm2.assign(n, 0.0);
    p.island_prev_norm2.assign(n, 0.0);
    p.island_beta.assign(n, 0.0);
  }
  const ContactSweepParams sp = sweepParams(p, o, o.nncg);
  for (int it = 0; it < o.iterations; ++it) {
    orderColours(p, o.randomize_order, rng_state);
    for (const std::int32_t ci : p.colour_order)
      forColour(
          p.colours[static_cast<size_t>(ci)], o.pool, [&](std::int32_t gi) { solveGroup(p, gi, bodies, o, o.nncg); },
          [&](int b0, int b1) { o.kernels->solve_normals(p.batches.data(), b0, b1, body_data, sp); });
    if (!p.batches.empty())  // a jointed scene without contacts has no friction pass to walk
      for (const std::int32_t ci : p.colour_order)
        forColour(
            p.colours[static_cast<size_t>(ci)], o.pool, [](std::int32_t) {},
            [&](int b0, int b1) { o.kernels->solve_friction(p.batches.data(), b0, b1, body_data, sp); });
    reduceSweep(p, true);
    stats.last_max_delta = 0;
    for (size_t i = 0; i < p.island_active.size(); ++i)
      if (p.island_active[i] > 0) stats.last_max_delta = std::max(stats.last_max_delta, p.island_delta[i]);
    if (!stopConverged(p, o, it + 1)) break;
    // No momentum after the last sweep: the result must be a PGS iterate.
    if (o.nncg && it + 1 < o.iterations) {
      islandBetas(p);
      for (const std::int32_t ci : p.colour_order)
        forColour(
            p.colours[static_cast<size_t>(ci)], o.pool,
            [&](std::int32_t gi) { groupMomentum(p, p.groups[static_cast<size_t>(gi)], bodies, o.dynamic_end); },
            [&](int b0, int b1) {
              o.kernels->momentum(p.batches.data(), b0, b1, body_data, p.island_beta.data(), sp);
            });
    }
  }
  for (const int n : p.island_iterations) stats.iterations = std::max(stats.iterations, n);
  return stats;
}

namespace {

// Something to correct: a push (bias > 0), or a pull on a row that can
// pull (lo < 0). A negative bias on a one-sided row only permits approach.
bool anyRowBias(const GraphProblem& p, Correction which) {
  for (const ConstraintRow& r : p.rows)
    if (r.correction == which && (r.bias_rhs > 0 || (r.bias_rhs < 0 && r.lo < 0))) return true;
  return false;
}

bool anyContactBias(const GraphProblem& p) {
  for (const ContactBatch& b : p.batches)
    for (int i = 0; i < kMaxPoints; ++i)
      for (int l = 0; l < kBatchLanes; ++l)
        if (b.p[i].bias[l] > 0) return true;
  return false;
}

void biasGroup(GraphProblem& p, std::int32_t gi, std::span<SolverBody> bodies, Correction which,
               const GraphSolveOptions& o) {
  const RowGroup& g = p.groups[static_cast<size_t>(gi)];
  if (!active(p, g.island)) return;
  Real max_delta = 0, max_lambda = 0;
  for (std::int32_t k = g.begin; k < g.end; ++k) {
    const ConstraintRow& r = p.rows[static_cast<size_t>(k)];
    if (r.correction != which) continue;
    Real& lambda = p.row_bias_lambda[static_cast<size_t>(k)];
    const Real jv = rowVelocity(r, bodies[static_cast<size_t>(r.body_a)], bodies[static_cast<size_t>(r.body_b)]);
    const Real delta = (r.bias_rhs - jv - r.cfm * lambda) * r.inv_diag;
    const Real next = std::clamp(lambda + o.sor * delta, r.lo, r.hi);
    const Real d = next - lambda;
    lambda = next;
    applyRow(r, bodies, o.dynamic_end, d);
    max_delta = std::max(max_delta, std::abs(d));
    max_lambda = std::max(max_lambda, std::abs(next));
  }
  p.group_delta[static_cast<size_t>(gi)] = max_delta;
  p.group_lambda[static_cast<size_t>(gi)] = max_lambda;
}

// One correction pass (pgs.cpp's solvePgsCorrection, by colour and with
// blocks for the contact normals), each island stopping on its own.
void biasPass(GraphProblem& p, std::span<SolverBody> bodies, Correction which, bool contacts,
              const GraphSolveOptions& o) {
  startSweeps(p);
  double* body_data = bodies.front().v.data();
  const ContactSweepParams sp = sweepParams(p, o, false);
  for (int it = 0; it < o.iterations; ++it) {
    for (const GraphColour& c : p.colours)
      forColour(
          c, o.pool, [&](std::int32_t gi) { biasGroup(p, gi, bodies, which, o); },
          [&](int b0, int b1) {
            if (contacts) o.kernels->solve_bias(p.batches.data(), b0, b1, body_data, sp);
          });
    reduceSweep(p, contacts);
    if (!stopConverged(p, o, it + 1)) break;
  }
}

}  // namespace

bool solveGraphCorrection(GraphProblem& p, std::span<SolverBody> bodies, std::span<SolverBody> pseudo,
                          const GraphSolveOptions& o) {
  if (p.empty()) return false;
  p.row_bias_lambda.assign(p.rows.size(), Real(0));
  if (anyRowBias(p, Correction::VelocityBias)) biasPass(p, bodies, Correction::VelocityBias, false, o);
  const bool contacts = anyContactBias(p);
  if (!contacts && !anyRowBias(p, Correction::PseudoVelocity)) return false;
  std::fill(p.row_bias_lambda.begin(), p.row_bias_lambda.end(), Real(0));
  for (ContactBatch& b : p.batches)
    for (int i = 0; i < kMaxPoints; ++i) std::fill(std::begin(b.p[i].lambda_bias), std::end(b.p[i].lambda_bias), 0.0);
  biasPass(p, pseudo, Correction::PseudoVelocity, contacts, o);
  return true;
}

void solveGraphRestitution(GraphProblem& p, std::span<SolverBody> bodies, const GraphSolveOptions& o) {
  if (p.batches.empty()) return;
  double* body_data = bodies.front().v.data();
  ContactSweepParams sp = sweepParams(p, o, false);
  sp.island_active = nullptr;
  for (const GraphColour& c : p.colours)
    forRange(o.pool, c.batch_end - c.batch_begin, c.batch_end - c.batch_begin, [&](int begin, int end) {
      o.kernels->restitution(p.batches.data(), c.batch_begin + begin, c.batch_begin + end, body_data, sp);
    });
}

}  // namespace cairn
