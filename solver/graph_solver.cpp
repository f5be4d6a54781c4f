#include "solver/graph_solver.hpp"

#include "solver/worker_pool.hpp"

#include <algorithm>
#include <cmath>
#include <ranges>

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

// Whether a row update writes solver body `body`: a dynamic one (the world
// is 0; static and kinematic bodies come from dynamic_end on).
inline bool writable(std::int32_t body, int dynamic_end) { return body > 0 && body < dynamic_end; }

// Adds M^-1 J^T d to the row's bodies that may be written (pgs.cpp's
// applyImpulse, without touching the read-only bodies).
inline void applyRow(const ConstraintRow& r, std::span<SolverBody> bodies, int dynamic_end, Real d) {
  if (writable(r.body_a, dynamic_end)) {
    SolverBody& a = bodies[static_cast<size_t>(r.body_a)];
    a.v += r.m_lin_a * d;
    a.w += r.m_ang_a * d;
  }
  if (writable(r.body_b, dynamic_end)) {
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

// --- Joints side by side (joint_lanes.hpp).

// Joints with more rows than this stay alone (the plan's waiting lists
// are sized by it; a joint has one to six rows, and one more for each
// active limit or motor axis).
constexpr int kMaxLaneRows = 16;

// Whether a group can take a lane: no friction row (its bounds follow its
// normal row's impulse), and every row between the same two bodies.
bool fitsLane(const GraphProblem& p, const RowGroup& g) {
  const int n = g.end - g.begin;
  if (n <= 0 || n > kMaxLaneRows) return false;
  const ConstraintRow& first = p.rows[static_cast<size_t>(g.begin)];
  for (std::int32_t k = g.begin; k < g.end; ++k) {
    const ConstraintRow& r = p.rows[static_cast<size_t>(k)];
    if (r.normal_row >= 0 || r.body_a != first.body_a || r.body_b != first.body_b) return false;
  }
  return true;
}

void put3(double (*dst)[kBatchLanes], int l, const Vec3& v) {
  for (int i = 0; i < 3; ++i) dst[i][l] = v[i];
}

// Lane l of `lane` takes group gi's rows.
void fillLane(GraphProblem& p, JointLanes& lane, int l, std::int32_t gi, int dynamic_end) {
  const RowGroup& g = p.groups[static_cast<size_t>(gi)];
  const ConstraintRow* rows = p.rows.data() + g.begin;
  lane.group[l] = gi;
  lane.body_a[l] = rows[0].body_a;
  lane.body_b[l] = rows[0].body_b;
  lane.island[l] = g.island;
  lane.used[l] = 1;
  lane.writes_a[l] = writable(rows[0].body_a, dynamic_end) ? 1 : 0;
  lane.writes_b[l] = writable(rows[0].body_b, dynamic_end) ? 1 : 0;
  for (int k = 0; k < lane.rows; ++k) {
    const ConstraintRow& r = rows[k];
    JointLaneRow& q = p.joint_lane_rows[static_cast<size_t>(lane.row_begin + k)];
    put3(q.j_lin_a, l, r.j_lin_a);
    put3(q.j_ang_a, l, r.j_ang_a);
    put3(q.j_lin_b, l, r.j_lin_b);
    put3(q.j_ang_b, l, r.j_ang_b);
    put3(q.m_lin_a, l, r.m_lin_a);
    put3(q.m_ang_a, l, r.m_ang_a);
    put3(q.m_lin_b, l, r.m_lin_b);
    put3(q.m_ang_b, l, r.m_ang_b);
    q.inv_diag[l] = r.inv_diag;
    q.rhs[l] = r.rhs;
    q.cfm[l] = r.cfm;
    q.lo[l] = r.lo;
    q.hi[l] = r.hi;
    q.lambda[l] = r.lambda;
    q.bias_rhs[l] = r.bias_rhs;
    q.correction[l] = static_cast<double>(r.correction);
  }
}

// Puts the joints of each colour that fit a lane into JointLanes of equal
// row counts, in group order; a row count that gathers one joint leaves it
// alone (a lane of one is the scalar visit with more work).
void planJointLanes(GraphProblem& p, int dynamic_end) {
  p.joint_lanes.clear();
  p.joint_lane_rows.clear();
  p.group_lanes.assign(p.groups.size(), kGroupAlone);
  std::int32_t waiting[kMaxLaneRows + 1][kBatchLanes];
  int count[kMaxLaneRows + 1] = {};
  const auto emit = [&](int n) {
    if (count[n] >= 2) {
      const auto at = static_cast<std::int32_t>(p.joint_lanes.size());
      JointLanes& lane = p.joint_lanes.emplace_back();
      std::fill(std::begin(lane.group), std::end(lane.group), -1);
      std::fill(std::begin(lane.body_a), std::end(lane.body_a), 0);  // an unused lane reads the world
      std::fill(std::begin(lane.body_b), std::end(lane.body_b), 0);
      std::fill(std::begin(lane.island), std::end(lane.island), 0);
      std::fill(std::begin(lane.used), std::end(lane.used), 0.0);
      std::fill(std::begin(lane.writes_a), std::end(lane.writes_a), 0.0);
      std::fill(std::begin(lane.writes_b), std::end(lane.writes_b), 0.0);
      lane.row_begin = static_cast<std::int32_t>(p.joint_lane_rows.size());
      lane.rows = n;
      p.joint_lane_rows.resize(p.joint_lane_rows.size() + static_cast<size_t>(n));  // zeros
      for (int l = 0; l < count[n]; ++l) {
        fillLane(p, lane, l, waiting[n][l], dynamic_end);
        p.group_lanes[static_cast<size_t>(waiting[n][l])] = at * kBatchLanes + l;
      }
    }
    count[n] = 0;
  };
  for (const GraphColour& c : p.colours) {
    for (std::int32_t gi = c.group_begin; gi < c.group_end; ++gi) {
      const RowGroup& g = p.groups[static_cast<size_t>(gi)];
      if (!fitsLane(p, g)) continue;
      const int n = g.end - g.begin;
      waiting[n][count[n]++] = gi;
      if (count[n] == kBatchLanes) emit(n);
    }
    for (int n = 1; n <= kMaxLaneRows; ++n) emit(n);
  }
}

// The lanes' impulses back to their rows, when the sweeps end.
void storeJointLanes(GraphProblem& p) {
  for (const JointLanes& lane : p.joint_lanes)
    for (int l = 0; l < kBatchLanes; ++l) {
      if (lane.group[l] < 0) continue;
      ConstraintRow* rows = p.rows.data() + p.groups[static_cast<size_t>(lane.group[l])].begin;
      for (int k = 0; k < lane.rows; ++k)
        rows[k].lambda = p.joint_lane_rows[static_cast<size_t>(lane.row_begin + k)].lambda[l];
    }
}

// Group gi's place in the lanes (JointLanes index * kBatchLanes + lane), or
// kGroupAlone when it is solved alone or no lanes were planned this solve.
std::int32_t laneOf(const GraphProblem& p, std::int32_t gi) {
  return p.joint_lanes.empty() ? kGroupAlone : p.group_lanes[static_cast<size_t>(gi)];
}

// Group gi's change in the last sweep, row k: in its lane or its row.
Real rowChange(const GraphProblem& p, std::int32_t gi, std::int32_t k) {
  const std::int32_t at = laneOf(p, gi);
  if (at == kGroupAlone) return p.row_change[static_cast<size_t>(p.groups[static_cast<size_t>(gi)].begin + k)];
  const JointLanes& lane = p.joint_lanes[static_cast<size_t>(at / kBatchLanes)];
  return p.joint_lane_rows[static_cast<size_t>(lane.row_begin + k)].change[at % kBatchLanes];
}

// The joints' largest change and impulse of lanes li's last visit, as
// solveGroup and biasGroup record them (nothing for a joint whose island
// has stopped).
void recordLanes(GraphProblem& p, std::int32_t li) {
  const JointLanes& lane = p.joint_lanes[static_cast<size_t>(li)];
  for (int l = 0; l < kBatchLanes; ++l) {
    const std::int32_t gi = lane.group[l];
    if (gi < 0 || !active(p, lane.island[l])) continue;
    p.group_delta[static_cast<size_t>(gi)] = lane.delta[l];
    p.group_lambda[static_cast<size_t>(gi)] = lane.lambda[l];
  }
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
constexpr double kGroupWork = 1.0 / kGroupsPerBatchVisit;

// Below this much work a pass (in batch visits), the flow schedule
// (colour_flow.hpp) is not planned. Planning costs about a batch visit per
// item, once a step, and a small island's colours rarely leave a second
// thread anything to do: pyramid-20's 111 batches, one to three a colour,
// planned a critical path of 110 visits (no gain), and the planning alone
// made its solve 3% slower on two threads; pyramid-40's 370 planned 276
// and solved 1.2 times faster than with the colours' barriers
// (docs/performance.md).
constexpr double kFlowWork = 256;

// Below this many manifold batches, consecutive passes do not overlap
// (pass_pipeline.hpp). On a pool, the trailing pass reads what the leading
// one has just written on the other core (the bodies, the batch's
// impulses), which made each of its batch visits about 1.6 times as long
// on the 2-core Xeon of docs/performance.md; it pays only where a pass
// trails the one before by a small share of its items. Measured, two
// threads against the barrier per colour: pyramid-10's 39 batches
// (trailing by 8) solved a quarter slower, pyramid-20's 111 (by 14) 8%
// faster, pyramid-30's 222 (by 17) 1.3 times faster; chain-100's joints
// alone (100 row groups, each an eighth of a batch visit) solved 15 to 40%
// slower, so row groups do not count. On one thread the interleave pays
// once the batches outgrow the core's cache, and costs nothing below:
// pyramid-20 (111 batches, 1.4 MB) solved as fast as pass after pass,
// pyramid-30 1.16 times, pyramid-40 1.07 times and the 5,050-box pyramid
// 1.24 to 1.31 times faster.
constexpr int kPipelineBatches = 96;

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
  sp.patch = o.patch_friction;
  sp.island_active = p.island_active.data();
  return sp;
}

// The items [begin, end) of a colour, which numbers its row groups, then
// its manifold batches.
template <class Groups, class Batches>
void forItems(const GraphColour& c, int begin, int end, Groups&& groups_fn, Batches&& batches_fn) {
  const int groups = c.group_end - c.group_begin;
  for (int i = begin; i < std::min(end, groups); ++i) groups_fn(c.group_begin + i);
  const int b0 = std::max(begin, groups) - groups, b1 = end - groups;
  if (b1 > b0) batches_fn(c.batch_begin + b0, c.batch_begin + b1);
}

// The items of a colour. Every item writes only its own constraints'
// bodies, so any split of the items among threads gives the same result.
template <class Groups, class Batches>
void forColour(const GraphColour& c, WorkerPool* pool, Groups&& groups_fn, Batches&& batches_fn) {
  const int groups = c.group_end - c.group_begin, batches = c.batch_end - c.batch_begin;
  forRange(pool, groups + batches, batches + kGroupWork * groups,
           [&](int begin, int end) { forItems(c, begin, end, groups_fn, batches_fn); });
}

// What one thread sweeps: a run of colours with their batches and groups,
// and the islands they belong to (the whole problem, or one of its parts).
struct Part {
  std::int32_t colour_begin = 0, colour_end = 0;
  std::int32_t batch_begin = 0, batch_end = 0;
  std::int32_t group_begin = 0, group_end = 0;
  std::int32_t island_begin = 0, island_end = 0;
};

Part wholeProblem(const GraphProblem& p) {
  return {0,
          static_cast<std::int32_t>(p.colours.size()),
          0,
          static_cast<std::int32_t>(p.batches.size()),
          0,
          static_cast<std::int32_t>(p.groups.size()),
          0,
          p.island_count};
}

// The parts a solve sweeps; a shuffled colour order (randomize_order) is
// one order over all colours, so then the whole problem is one part.
int partCount(const GraphProblem& p, const GraphSolveOptions& o) {
  return p.part_colour.empty() || o.randomize_order ? 1 : static_cast<int>(p.part_colour.size()) - 1;
}

Part partOf(const GraphProblem& p, const GraphSolveOptions& o, int k) {
  if (partCount(p, o) == 1) return wholeProblem(p);
  Part part;
  part.colour_begin = p.part_colour[static_cast<size_t>(k)];
  part.colour_end = p.part_colour[static_cast<size_t>(k) + 1];
  part.island_begin = p.part_island[static_cast<size_t>(k)];
  part.island_end = p.part_island[static_cast<size_t>(k) + 1];
  if (part.colour_end > part.colour_begin) {
    const GraphColour& first = p.colours[static_cast<size_t>(part.colour_begin)];
    const GraphColour& last = p.colours[static_cast<size_t>(part.colour_end) - 1];
    part = {part.colour_begin, part.colour_end, first.batch_begin, last.batch_end, first.group_begin,
            last.group_end,    part.island_begin, part.island_end};
  }
  return part;
}

// Runs fn(k, part k, options) for every part: side by side on the pool's
// threads when there are several (each then sweeps its colours alone, with
// no pool of its own), else on the calling thread with the pool for the
// colours.
template <class F>
void forParts(const GraphProblem& p, const GraphSolveOptions& o, F&& fn) {
  const int parts = partCount(p, o);
  if (parts == 1 || !o.pool) {
    for (int k = 0; k < parts; ++k) fn(k, partOf(p, o, k), o);
    return;
  }
  GraphSolveOptions alone = o;
  alone.pool = nullptr;
  o.pool->parallelFor(parts, [&](int begin, int end) {
    for (int k = begin; k < end; ++k) fn(k, partOf(p, o, k), alone);
  });
}

// Whether the passes over this problem follow its flow schedule
// (colour_flow.hpp): one part in colour order with a pool, and a schedule
// that saves at least the work a handover to the pool costs.
bool useFlow(GraphProblem& p, const GraphSolveOptions& o) {
  if (!o.pool || o.randomize_order || partCount(p, o) != 1) return false;
  const double work = static_cast<double>(p.batches.size()) + kGroupWork * static_cast<double>(p.groups.size());
  if (work < kFlowWork) return false;
  if (!p.flow.planned()) p.flow.plan(p, o.pool->threads(), o.dynamic_end, kParallelWork);
  return p.flow.ready();
}

// One pass over `colours` in turn: by the flow schedule (`flow`: then the
// colours are all of them, in order), else colour by colour.
template <class Colours, class Groups, class Batches>
void forColours(GraphProblem& p, bool flow, WorkerPool* pool, const Colours& colours, Groups&& groups_fn,
                Batches&& batches_fn) {
  if (flow) {
    p.flow.run(*pool, [&](const FlowItem& it) {
      forItems(p.colours[static_cast<size_t>(it.colour)], it.item, it.item + 1, groups_fn, batches_fn);
    });
    return;
  }
  for (const std::int32_t ci : colours) forColour(p.colours[static_cast<size_t>(ci)], pool, groups_fn, batches_fn);
}

// The per-island figures a run of sweeps stops on: the velocity sweeps'
// (and a correction pass of its own), or the correction's swept with the
// velocities (sweepPart).
struct IslandFigures {
  std::vector<double>& active;  // 1 while the island's sweeps go on
  std::vector<double>& delta;   // this sweep's largest change
  std::vector<double>& lambda;  // and largest impulse
  std::vector<int>* iterations;  // sweeps so far (null: not counted)
};
IslandFigures sweepFigures(GraphProblem& p) {
  return {p.island_active, p.island_delta, p.island_lambda, &p.island_iterations};
}
IslandFigures fusedBiasFigures(GraphProblem& p) { return {p.bias_active, p.bias_delta, p.bias_lambda, nullptr}; }

// A lane figure of the batches: a pass's largest change or impulse.
using LaneFigure = double (ContactBatch::*)[kBatchLanes];

// x becomes the larger of x and d, and NaN once either is: a non-finite
// island never looks converged, and the result does not depend on the
// order the figures are folded in (so not on which thread folded which).
void foldFigure(double& x, double d) {
  if (x == x && !(x >= d)) x = d;
}

// Where a fold's figures sit in an island's four of lane_figures.
constexpr int kSweepFigures = 0, kBiasFigures = 2;

// The lane figures of batches [b0, b1) into the calling thread's row of
// GraphProblem::lane_figures, after their friction visit: the sweep's
// where the island's sweeps go on, and with `bias` the correction's where
// its own go on.
void foldLaneFigures(GraphProblem& p, int b0, int b1, bool bias) {
  const int thread = p.lane_figure_threads > 1 ? WorkerPool::currentThread() : 0;
  double* acc = p.lane_figures.data() + static_cast<size_t>(thread) * static_cast<size_t>(p.island_count) * 4;
  for (int bi = b0; bi < b1; ++bi) {
    const ContactBatch& b = p.batches[static_cast<size_t>(bi)];
    for (int l = 0; l < kBatchLanes; ++l) {
      if (b.count[l] <= 0) continue;
      const size_t isl = static_cast<size_t>(b.island[l]);
      double* a = acc + 4 * isl;
      if (p.island_active[isl] > 0) {
        foldFigure(a[kSweepFigures], b.sweep_delta[l]);
        foldFigure(a[kSweepFigures + 1], b.sweep_lambda[l]);
      }
      if (bias && p.bias_active[isl] > 0) {
        foldFigure(a[kBiasFigures], b.bias_delta[l]);
        foldFigure(a[kBiasFigures + 1], b.bias_lambda[l]);
      }
    }
  }
}

// Empties every thread's lane figures of the part's islands, before a
// sweep folds into them.
void clearLaneFigures(GraphProblem& p, const Part& part) {
  const auto islands = static_cast<size_t>(p.island_count);
  for (size_t t = 0; t < static_cast<size_t>(p.lane_figure_threads); ++t)
    std::fill(p.lane_figures.begin() + static_cast<std::ptrdiff_t>(4 * (t * islands + static_cast<size_t>(part.island_begin))),
              p.lane_figures.begin() + static_cast<std::ptrdiff_t>(4 * (t * islands + static_cast<size_t>(part.island_end))),
              0.0);
}

// The part's row groups' largest change and impulse into their islands'
// figures, where the islands' sweeps go on.
void foldGroupFigures(const GraphProblem& p, IslandFigures f, const Part& part) {
  for (std::int32_t g = part.group_begin; g < part.group_end; ++g) {
    const auto i = static_cast<size_t>(p.groups[static_cast<size_t>(g)].island);
    if (f.active[i] > 0) {
      foldFigure(f.delta[i], p.group_delta[static_cast<size_t>(g)]);
      foldFigure(f.lambda[i], p.group_lambda[static_cast<size_t>(g)]);
    }
  }
}

// Each island's largest change and impulse of the sweep: from the lane
// figures the threads folded (`which`: kSweepFigures or kBiasFigures; a
// part without batches folded none, and its rows hold zeros), and the row
// groups' with `groups`.
void gatherSweep(GraphProblem& p, IslandFigures f, const Part& part, int which, bool groups) {
  const auto islands = static_cast<size_t>(p.island_count);
  for (std::int32_t k = part.island_begin; k < part.island_end; ++k) {
    const auto i = static_cast<size_t>(k);
    f.delta[i] = 0;
    f.lambda[i] = 0;
    for (size_t t = 0; t < static_cast<size_t>(p.lane_figure_threads); ++t) {
      const double* a = p.lane_figures.data() + 4 * (t * islands + i) + which;
      foldFigure(f.delta[i], a[0]);
      foldFigure(f.lambda[i], a[1]);
    }
  }
  if (groups) foldGroupFigures(p, f, part);
}

// Each island's largest change and impulse of the sweep, read back from
// the batches (the correction's own sweeps, which have no friction visit
// to fold them in): the lanes' figures `delta` and `lambda` (none when
// null), and the row groups' with `groups`.
void reduceSweep(GraphProblem& p, IslandFigures f, const Part& part, LaneFigure delta, LaneFigure lambda,
                 bool groups) {
  std::fill(f.delta.begin() + part.island_begin, f.delta.begin() + part.island_end, 0.0);
  std::fill(f.lambda.begin() + part.island_begin, f.lambda.begin() + part.island_end, 0.0);
  const auto on = [&](std::int32_t island) { return f.active[static_cast<size_t>(island)] > 0; };
  const auto fold = [&](std::int32_t island, double d, double l) {
    const size_t i = static_cast<size_t>(island);
    foldFigure(f.delta[i], d);
    foldFigure(f.lambda[i], l);
  };
  if (delta)
    for (std::int32_t bi = part.batch_begin; bi < part.batch_end; ++bi) {
      const ContactBatch& b = p.batches[static_cast<size_t>(bi)];
      for (int l = 0; l < kBatchLanes; ++l)
        if (b.count[l] > 0 && on(b.island[l])) fold(b.island[l], (b.*delta)[l], (b.*lambda)[l]);
    }
  if (groups) foldGroupFigures(p, f, part);
}

// Stops the islands that reached the tolerance or a round-off fixed point;
// returns whether any island goes on.
bool stopConverged(IslandFigures f, const Part& part, const GraphSolveOptions& o, int sweeps) {
  bool any = false;
  for (std::int32_t k = part.island_begin; k < part.island_end; ++k) {
    const size_t i = static_cast<size_t>(k);
    if (f.active[i] == 0) continue;
    if (f.iterations) (*f.iterations)[i] = sweeps;
    const double d = f.delta[i];
    if ((o.tolerance > 0 && d <= o.tolerance) || d <= kRoundOff * f.lambda[i]) f.active[i] = 0;
    else any = true;
  }
  return any;
}

// beta per island from this sweep's squared change (summed in storage
// order); -1 for islands that have stopped.
void islandBetas(GraphProblem& p, const Part& part) {
  std::fill(p.island_norm2.begin() + part.island_begin, p.island_norm2.begin() + part.island_end, 0.0);
  for (std::int32_t bi = part.batch_begin; bi < part.batch_end; ++bi) {
    const ContactBatch& b = p.batches[static_cast<size_t>(bi)];
    for (int l = 0; l < kBatchLanes; ++l)
      if (b.count[l] > 0) p.island_norm2[static_cast<size_t>(b.island[l])] += b.change2[l];
  }
  for (std::int32_t gi = part.group_begin; gi < part.group_end; ++gi) {
    const RowGroup& g = p.groups[static_cast<size_t>(gi)];
    for (std::int32_t k = 0; k < g.end - g.begin; ++k) {
      const Real d = rowChange(p, gi, k);
      p.island_norm2[static_cast<size_t>(g.island)] += d * d;
    }
  }
  for (std::int32_t k = part.island_begin; k < part.island_end; ++k) {
    const size_t i = static_cast<size_t>(k);
    if (p.island_active[i] == 0) {
      p.island_beta[i] = -1;
      continue;
    }
    const double prev = p.island_prev_norm2[i];
    p.island_beta[i] = prev > 0 ? p.island_norm2[i] / prev : 0.0;
    p.island_prev_norm2[i] = p.island_norm2[i];
  }
}

// The order of this sweep's colours: the part's in order, or (whole
// problem only) a seeded shuffle of all of them.
void orderColours(std::vector<std::int32_t>& order, const Part& part, bool randomize, std::uint64_t& rng_state) {
  const size_t n = static_cast<size_t>(part.colour_end - part.colour_begin);
  order.resize(n);
  for (size_t i = 0; i < n; ++i) order[i] = part.colour_begin + static_cast<std::int32_t>(i);
  if (randomize)
    for (size_t i = n; i > 1; --i) std::swap(order[i - 1], order[nextRandom(rng_state) % i]);
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

// Something to correct: a push (bias > 0), or a pull on a row that can
// pull (lo < 0). A negative bias on a one-sided row only permits approach.
bool anyRowBias(const GraphProblem& p, Correction which) {
  for (const ConstraintRow& r : p.rows)
    if (r.correction == which && (r.bias_rhs > 0 || (r.bias_rhs < 0 && r.lo < 0))) return true;
  return false;
}

// The correction pass starts from no impulse each (sub)step.
void clearBiasImpulses(GraphProblem& p) {
  for (ContactBatch& b : p.batches)
    for (int i = 0; i < kMaxPoints; ++i) std::fill(std::begin(b.p[i].lambda_bias), std::end(b.p[i].lambda_bias), 0.0);
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

// One sweep of a correction pass over a part, by colour: its row groups'
// rows of kind `which` (with `groups`) and its manifolds' blocks (with
// `contacts`, on `bodies` as sp says); returns whether any of the part's
// islands goes on.
bool biasSweep(GraphProblem& p, const Part& part, bool flow, std::span<SolverBody> bodies, Correction which,
               bool contacts, bool groups, IslandFigures f, const ContactSweepParams& sp, const GraphSolveOptions& o,
               int sweeps) {
  double* body_data = bodies.front().v.data();
  forColours(
      p, flow, o.pool, std::views::iota(part.colour_begin, part.colour_end),
      [&](std::int32_t gi) {
        if (!groups) return;
        const std::int32_t at = laneOf(p, gi);
        if (at == kGroupAlone) {
          biasGroup(p, gi, bodies, which, o);
        } else if (at % kBatchLanes == 0) {  // a joint in another's lanes is visited with them
          o.kernels->joint_lanes_bias(p.joint_lanes.data(), p.joint_lane_rows.data(), at / kBatchLanes,
                                      at / kBatchLanes + 1, body_data, static_cast<int>(which), sp);
          recordLanes(p, at / kBatchLanes);
        }
      },
      [&](int b0, int b1) {
        if (contacts) o.kernels->solve_bias(p.batches.data(), b0, b1, body_data, sp);
      });
  reduceSweep(p, f, part, contacts ? &ContactBatch::bias_delta : nullptr, &ContactBatch::bias_lambda, groups);
  return stopConverged(f, part, o, sweeps);
}

// The passes of a sweep over a part's constraints.
enum class Pass { WarmStart, Normals, Friction, Momentum };

// Whether the passes of this problem overlap (pass_pipeline.hpp), side by
// side on the pool or interleaved on one thread: one part in colour order,
// no flow schedule (which shares each pass's colours between the threads
// instead, and is chosen past its own, larger size), and enough batches.
bool usePipeline(GraphProblem& p, const GraphSolveOptions& o, bool flow) {
  if (!o.overlap_passes || flow || o.randomize_order || partCount(p, o) != 1) return false;
  if (static_cast<int>(p.batches.size()) < kPipelineBatches) return false;
  if (!p.pipeline.planned()) p.pipeline.plan(p, o.dynamic_end);
  return true;
}

// Warm start and the velocity sweeps of one part. `order` is this part's
// own colour order (parts never randomize: the step makes none then).
// With p.correction_swept, the split-impulse correction's sweeps on
// `pseudo` too: each in the normal pass of a velocity sweep, the batch
// visited for both at once, and alone past the velocity sweeps' end. Its
// islands stop by its own figures (bias_active), and it reads nothing the
// velocity sweeps write, so its bits are those of a pass of its own.
GraphSolveStats sweepPart(GraphProblem& p, const Part& part, std::vector<std::int32_t>& order,
                          std::span<SolverBody> bodies, std::span<SolverBody> pseudo, const GraphSolveOptions& o,
                          std::uint64_t& rng_state) {
  GraphSolveStats stats;
  double* body_data = bodies.front().v.data();
  const bool flow = useFlow(p, o);
  const bool pipeline = usePipeline(p, o, flow);
  const bool overlap = pipeline || (flow && o.overlap_passes);
  const ContactSweepParams warm = sweepParams(p, o, false);
  const ContactSweepParams sp = sweepParams(p, o, o.nncg);
  ContactSweepParams sp_bias = sweepParams(p, o, false);  // the correction alone
  sp_bias.island_active = p.bias_active.data();
  ContactSweepParams sp_both = sp;  // a velocity sweep's normal pass with the correction's
  bool bias_on = p.correction_swept;
  int bias_sweeps = 0;
  if (bias_on) {
    sp_both.pseudo = pseudo.front().v.data();
    sp_both.pseudo_active = p.bias_active.data();
  }

  const auto groupFn = [&](Pass pass) {
    return [&, pass](std::int32_t gi) {
      const std::int32_t at = laneOf(p, gi);
      switch (pass) {
        case Pass::WarmStart: {  // the carried impulses act before the first sweep
          const RowGroup& g = p.groups[static_cast<size_t>(gi)];
          for (std::int32_t k = g.begin; k < g.end; ++k) {
            const ConstraintRow& r = p.rows[static_cast<size_t>(k)];
            if (r.lambda != 0) applyRow(r, bodies, o.dynamic_end, r.lambda);
          }
          break;
        }
        case Pass::Normals:
          if (at == kGroupAlone) solveGroup(p, gi, bodies, o, o.nncg);
          else if (at % kBatchLanes == 0) {
            o.kernels->solve_joint_lanes(p.joint_lanes.data(), p.joint_lane_rows.data(), at / kBatchLanes,
                                         at / kBatchLanes + 1, body_data, sp);
            recordLanes(p, at / kBatchLanes);
          }
          break;  // a joint in another's lanes is visited with them
        case Pass::Friction: break;  // a group's friction rows go with its normal rows
        case Pass::Momentum:
          if (at == kGroupAlone) groupMomentum(p, p.groups[static_cast<size_t>(gi)], bodies, o.dynamic_end);
          else if (at % kBatchLanes == 0)
            o.kernels->joint_lanes_momentum(p.joint_lanes.data(), p.joint_lane_rows.data(), at / kBatchLanes,
                                            at / kBatchLanes + 1, body_data, p.island_beta.data(), sp);
          break;
      }
    };
  };
  const auto batchFn = [&](Pass pass) {
    return [&, pass](int b0, int b1) {
      switch (pass) {
        case Pass::WarmStart: o.kernels->warm_start(p.batches.data(), b0, b1, body_data, warm); break;
        case Pass::Normals:
          o.kernels->solve_normals(p.batches.data(), b0, b1, body_data, bias_on ? sp_both : sp);
          break;
        case Pass::Friction:
          o.kernels->solve_friction(p.batches.data(), b0, b1, body_data, sp);
          foldLaneFigures(p, b0, b1, bias_on);  // the batches' sweep is done
          break;
        case Pass::Momentum:
          o.kernels->momentum(p.batches.data(), b0, b1, body_data, p.island_beta.data(), sp);
          break;
      }
    };
  };
  // Without overlap a pass runs as soon as it is queued (the warm start in
  // storage order, the others in this sweep's colour order, so a shuffled
  // order is the one of its own sweep); with it, the passes queued since
  // the last sweep's end overlap at the next: interleaved by the flow
  // schedule's threads, else by the pipeline.
  Pass passes[kMaxOverlappedPasses];
  int pending = 0;
  const auto queue = [&](Pass pass) {
    if (overlap) {
      passes[pending++] = pass;
    } else if (pass == Pass::WarmStart) {
      forColours(p, flow, o.pool, std::views::iota(part.colour_begin, part.colour_end), groupFn(pass), batchFn(pass));
    } else {
      forColours(p, flow, o.pool, order, groupFn(pass), batchFn(pass));
    }
  };
  const auto endSweep = [&] {
    if (pending == 0) return;
    const auto item = [&](int j, const FlowItem& it) {
      forItems(p.colours[static_cast<size_t>(it.colour)], it.item, it.item + 1, groupFn(passes[j]),
               batchFn(passes[j]));
    };
    if (flow) p.flow.runInterleaved(*o.pool, pending, item);
    else if (o.pool) p.pipeline.run(*o.pool, pending, item);
    else p.pipeline.runInterleaved(pending, item);
    pending = 0;
  };

  queue(Pass::WarmStart);
  const bool batches = part.batch_end > part.batch_begin;
  for (int it = 0; it < o.iterations; ++it) {
    if (o.randomize_order || it == 0) orderColours(order, part, o.randomize_order, rng_state);
    clearLaneFigures(p, part);  // before the passes: without overlap, a queued pass runs at once
    queue(Pass::Normals);
    if (batches) queue(Pass::Friction);  // a jointed scene without contacts has no friction pass
    endSweep();
    gatherSweep(p, sweepFigures(p), part, kSweepFigures, true);
    if (bias_on) {
      gatherSweep(p, fusedBiasFigures(p), part, kBiasFigures, false);
      bias_on = stopConverged(fusedBiasFigures(p), part, o, ++bias_sweeps);
    }
    stats.last_max_delta = 0;
    for (std::int32_t i = part.island_begin; i < part.island_end; ++i)
      if (p.island_active[static_cast<size_t>(i)] > 0)
        stats.last_max_delta = std::max(stats.last_max_delta, p.island_delta[static_cast<size_t>(i)]);
    stats.iterations = it + 1;
    if (!stopConverged(sweepFigures(p), part, o, it + 1)) break;
    // No momentum after the last sweep: the result must be a PGS iterate.
    if (o.nncg && it + 1 < o.iterations) {
      islandBetas(p, part);
      queue(Pass::Momentum);
    }
  }
  // The correction's sweeps left when the velocities' stopped first (the
  // momentum queued after a stopping sweep never runs: it was the last).
  for (; bias_on && bias_sweeps < o.iterations;)
    bias_on = biasSweep(p, part, flow, pseudo, Correction::PseudoVelocity, true, false, fusedBiasFigures(p), sp_bias, o,
                        ++bias_sweeps);
  return stats;
}

}  // namespace

GraphSolveStats solveGraph(GraphProblem& p, std::span<SolverBody> bodies, const GraphSolveOptions& o,
                           std::uint64_t& rng_state, std::span<SolverBody> pseudo) {
  GraphSolveStats stats;
  p.correction_swept = false;
  if (p.empty()) return stats;
  startSweeps(p);
  // Joints in lanes where the colours are swept one after another: the
  // flow schedule and the pipeline start an item once the items it
  // depends on are done, and a joint visited with its lanes' first one
  // would look done before it is. (Both are planned here as sweepPart
  // would plan them.)
  p.joint_lanes.clear();
  if (o.joint_lanes && o.kernels && p.groups.size() >= 2) {
    const bool one_part = partCount(p, o) == 1;
    const bool flow = one_part && useFlow(p, o);
    if (!flow && !(one_part && usePipeline(p, o, flow))) planJointLanes(p, o.dynamic_end);
  }
  // The contacts' split-impulse correction with the velocity sweeps, where
  // it is the whole pseudo-velocity pass (no row group has a pseudo row)
  // and its colour order is the velocities' (not shuffled).
  if (!pseudo.empty() && o.sweep_correction && !o.randomize_order && anyContactBias(p) &&
      !anyRowBias(p, Correction::PseudoVelocity)) {
    p.correction_swept = true;
    clearBiasImpulses(p);
    const size_t n = static_cast<size_t>(p.island_count);
    p.bias_active.assign(n, 1.0);
    p.bias_delta.assign(n, 0.0);
    p.bias_lambda.assign(n, 0.0);
  }
  if (o.nncg) {
    p.row_change.assign(p.rows.size(), Real(0));
    p.row_dir.assign(p.rows.size(), Real(0));
    const size_t n = static_cast<size_t>(p.island_count);
    p.island_norm2.assign(n, 0.0);
    p.island_prev_norm2.assign(n, 0.0);
    p.island_beta.assign(n, 0.0);
  }
  p.lane_figure_threads = o.pool ? o.pool->threads() : 1;
  p.lane_figures.resize(static_cast<size_t>(p.lane_figure_threads) * static_cast<size_t>(p.island_count) * 4);
  const int parts = partCount(p, o);
  p.part_stats.assign(static_cast<size_t>(parts), GraphSolveStats{});
  p.part_order.resize(static_cast<size_t>(parts));
  forParts(p, o, [&](int k, const Part& part, const GraphSolveOptions& po) {
    p.part_stats[static_cast<size_t>(k)] =
        sweepPart(p, part, p.part_order[static_cast<size_t>(k)], bodies, pseudo, po, rng_state);
  });
  storeJointLanes(p);
  // The sweeps ended with the part that swept longest: its islands'
  // largest change is the last sweep's (as one part would report it).
  for (const int n : p.island_iterations) stats.iterations = std::max(stats.iterations, n);
  for (const GraphSolveStats& st : p.part_stats)
    if (st.iterations == stats.iterations) stats.last_max_delta = std::max(stats.last_max_delta, st.last_max_delta);
  return stats;
}

namespace {

// One correction pass (pgs.cpp's solvePgsCorrection, by colour and with
// blocks for the contact normals), each island stopping on its own, each
// part on its own thread.
void biasPass(GraphProblem& p, std::span<SolverBody> bodies, Correction which, bool contacts,
              const GraphSolveOptions& o) {
  startSweeps(p);
  for (JointLaneRow& r : p.joint_lane_rows) std::fill(std::begin(r.lambda_bias), std::end(r.lambda_bias), 0.0);
  const ContactSweepParams sp = sweepParams(p, o, false);
  forParts(p, o, [&](int, const Part& part, const GraphSolveOptions& po) {
    const bool flow = useFlow(p, po);
    for (int it = 0; it < po.iterations; ++it)
      if (!biasSweep(p, part, flow, bodies, which, contacts, true, sweepFigures(p), sp, po, it + 1)) break;
  });
}

}  // namespace

bool solveGraphCorrection(GraphProblem& p, std::span<SolverBody> bodies, std::span<SolverBody> pseudo,
                          const GraphSolveOptions& o) {
  if (p.empty()) return false;
  p.row_bias_lambda.assign(p.rows.size(), Real(0));
  if (anyRowBias(p, Correction::VelocityBias)) biasPass(p, bodies, Correction::VelocityBias, false, o);
  if (p.correction_swept) return true;  // swept with the velocities (solveGraph)
  const bool contacts = anyContactBias(p);
  if (!contacts && !anyRowBias(p, Correction::PseudoVelocity)) return false;
  std::fill(p.row_bias_lambda.begin(), p.row_bias_lambda.end(), Real(0));
  clearBiasImpulses(p);
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
