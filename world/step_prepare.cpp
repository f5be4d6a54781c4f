// Stages 3 (solver order) and 5 (prepare) of the step.
//
// Solver order: the awake dynamic bodies island by island, then the
// kinematic bodies, then one static body standing for the world and every
// static or sleeping body (solver/solver_body.hpp).
//
// Prepare: every constraint of an awake island becomes solver data for this
// substep. The graph's layout is made at a step's first substep and kept
// for the others, and so, unless SolverSettings::
// prepare_contacts_each_substep asks otherwise, are the contact lanes,
// whose separations later substeps only measure again.
// Islands solved by PGS go into the constraint graph
// (solver/graph_solver.hpp): each contact manifold as one lane of a
// ContactBatch, each joint (and each contact with rolling or torsional
// friction) as a group of generic rows. Islands solved directly or exactly
// get generic rows, island by island, as those solvers read them.
//
// The graph's colours fix the Gauss-Seidel order of the sweeps. The
// constraints are sorted by level, the distance of their bodies from the
// static world in the constraint graph, which is the order that carries a
// stack's support from the ground up within one sweep (Erleben,
// "Velocity-based shock propagation for multibody dynamics animation", ACM
// TOG 26(2), 2007, orders by the same levels). Each level's constraints are
// then coloured greedily (Box2D v3's constraint_graph.c colours the whole
// graph so), the colours of a level after those of the level below. No two
// constraints of one colour share a dynamic body, so a colour can be solved
// by vector lanes and threads at once; the result depends only on the
// colouring, never on the instruction set or the thread count.
// docs/performance.md measures the order against Box2D's plain greedy
// colouring and against one colour per constraint.
#include "world/grow_capacity.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/step_stages.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

namespace cairn::detail {

namespace {

using Item = GraphItem;

std::int32_t solverIndex(const StepContext& ctx, BodyId id) {
  return id.isWorld() ? ctx.static_index : ctx.solver_of_body[static_cast<size_t>(id.index)];
}

BodyView solverView(const WorldImpl& w, const StepContext& ctx, BodyId id) {
  BodyView v = w.view(id);
  v.solver_index = solverIndex(ctx, id);
  return v;
}

std::int32_t islandOf(const StepContext& ctx, BodyId a, BodyId b) {
  const std::int32_t ia = a.isWorld() ? -1 : ctx.body_island[static_cast<size_t>(a.index)];
  return ia >= 0 ? ia : (b.isWorld() ? -1 : ctx.body_island[static_cast<size_t>(b.index)]);
}

bool usesRowGroup(const Contact& c) { return c.rolling_friction > 0 || c.torsional_friction > 0; }

int tri(int i, int j) { return i * (i + 1) / 2 + j; }

// Cholesky factors of the blocks A_b + eps I of a batch's eight lanes,
// eps = 1e-12 of the block's largest diagonal: a face manifold's A_b is
// singular (4 coplanar points fix 3 motions), and the regularisation picks,
// among the impulses that give the same motion, one of least norm (pgs.cpp's
// factorBlock). The lanes are the inner loop: a factor is a chain of four
// square roots and six divisions, each waiting for the last, and eight
// independent chains side by side keep the divider busy where one chain
// left it waiting (a fifth of the scalar fill's time when each lane was factored
// alone). Each lane's arithmetic is the same as alone, so are its bits.
void factorBatch(ContactBatch& b) {
  double eps[kBatchLanes];
  for (int l = 0; l < kBatchLanes; ++l) {
    Real top = 0;
    for (int i = 0; i < 4; ++i) top = std::max(top, b.block[tri(i, i)][l]);
    eps[l] = Real(1e-12) * top;
  }
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j <= i; ++j)
      for (int l = 0; l < kBatchLanes; ++l) {
        Real sum = b.block[tri(i, j)][l] + (i == j ? eps[l] : Real(0));
        for (int k = 0; k < j; ++k) sum -= b.factor[tri(i, k)][l] * b.factor[tri(j, k)][l];
        b.factor[tri(i, j)][l] = i == j ? std::sqrt(std::max(sum, eps[l])) : sum / b.factor[tri(j, j)][l];
      }
}

// The effective masses 1 / (A_ii + cfm) of a batch's rows, from the
// diagonals the fill kernel left in their place (0: no row), lanes innermost for
// the same reason as factorBatch.
void invertRowMasses(ContactBatch& b) {
  for (int i = 0; i < kMaxPoints; ++i) {
    ContactBatch::Point& q = b.p[i];
    for (Real* m : {q.normal_mass, q.tangent_mass[0], q.tangent_mass[1]})
      for (int l = 0; l < kBatchLanes; ++l) m[l] = m[l] > 0 ? 1 / m[l] : Real(0);
  }
}

// A point past a manifold's count reads as zeros; a padding lane (the rest
// of a colour's last batch) is the world on both sides, with no points.
const ContactPointState kNoPoint;
const Contact kPadding;

// What the refresh kernel reads for one lane at a later substep, and the
// fill kernel with the rest: the two bodies' present poses and the points'
// anchors fixed in them.
void gatherPoses(ContactBatchInput& in, int lane, const Contact& c, const WorldImpl& w) {
  const auto side = [&](ContactBatchInput::Side& s, BodyId id) {
    static const Body kWorld;  // the world: at the origin, unrotated
    const Body& b = id.isWorld() ? kWorld : w.bodies_[static_cast<size_t>(id.index)];
    for (int k = 0; k < 3; ++k) s.x[k][lane] = b.position[k];
    for (int k = 0; k < 4; ++k) s.q[k][lane] = b.orientation.coeffs()[k];  // x, y, z, w
  };
  side(in.a, c.body_a);
  side(in.b, c.body_b);
  for (int i = 0; i < kMaxPoints; ++i) {
    const ContactPointState& p = i < c.count ? c.points[i] : kNoPoint;
    for (int k = 0; k < 3; ++k) {
      in.p[i].local_a[k][lane] = p.local_a[k];
      in.p[i].local_b[k][lane] = p.local_b[k];
    }
  }
}

// A body's mass data and velocities into one side of a lane, as
// WorldImpl::view has them (Body::solverInvMass and solverInvInertia; the
// world unlocked, at rest, without either) but read
// straight from the body: a view is 300 bytes made twice a manifold, and
// the 5,050-box pyramid made 28,000 of them a step.
void gatherSide(ContactBatchInput::Side& s, int lane, BodyId id, const WorldImpl& w) {
  if (id.isWorld()) {
    for (int k = 0; k < 3; ++k) {
      s.lin_factor[k][lane] = 1;
      s.v[k][lane] = 0;
      s.w[k][lane] = 0;
      for (int j = 0; j < 3; ++j) s.inv_inertia[3 * k + j][lane] = 0;
    }
    s.inv_mass[lane] = 0;
    return;
  }
  const Body& b = w.bodies_[static_cast<size_t>(id.index)];
  const Mat3 inv_inertia = b.solverInvInertia();
  for (int k = 0; k < 3; ++k) {
    s.lin_factor[k][lane] = b.linear_factor[k];
    s.v[k][lane] = b.linear_velocity[k];
    s.w[k][lane] = b.angular_velocity[k];
    for (int j = 0; j < 3; ++j) s.inv_inertia[3 * k + j][lane] = inv_inertia(k, j);
  }
  s.inv_mass[lane] = b.solverInvMass();
}

// One manifold and its bodies (solver indices ia, ib) into one lane of the
// fill kernel's input (solver/contact_batch.hpp lists the fields; the
// kernel makes the lane): the poses and anchors as the refresh reads them,
// then the rest.
void gatherLane(ContactBatchInput& in, ContactBatch& batch, int lane, const Contact& c, std::int32_t ia, std::int32_t ib,
                std::int32_t island, const WorldImpl& w) {
  gatherPoses(in, lane, c, w);
  batch.body_a[lane] = ia;
  batch.body_b[lane] = ib;
  batch.island[lane] = island;
  batch.count[lane] = c.count;
  gatherSide(in.a, lane, c.body_a, w);
  gatherSide(in.b, lane, c.body_b, w);
  for (int k = 0; k < 3; ++k) in.n[k][lane] = c.normal[k];
  in.friction[lane] = c.friction;
  in.restitution[lane] = c.restitution;
  for (int i = 0; i < kMaxPoints; ++i) {
    ContactBatchInput::Point& q = in.p[i];
    const ContactPointState& s = i < c.count ? c.points[i] : kNoPoint;
    for (int k = 0; k < 3; ++k) q.friction_impulse[k][lane] = s.friction_impulse[k];
    q.approach_speed[lane] = s.approach_speed;
    q.max_impulse[lane] = s.max_impulse;
    q.normal_impulse[lane] = s.normal_impulse;
  }
}

// Whether any point of a batch has a restitution target.
bool anyBounce(const ContactBatch& b) {
  for (const ContactBatch::Point& q : b.p)
    for (const double v : q.bounce)
      if (v != 0) return true;
  return false;
}

}  // namespace

void orderSolverBodies(WorldImpl& w, StepContext& ctx) {
  const size_t n = w.bodies_.size();
  // Counting sort of the awake dynamic bodies by island, in body order.
  ctx.island_first_body.assign(static_cast<size_t>(ctx.island_count) + 1, 0);
  for (size_t i = 0; i < n; ++i)
    if (ctx.body_island[i] >= 0) ++ctx.island_first_body[static_cast<size_t>(ctx.body_island[i]) + 1];
  for (size_t k = 1; k < ctx.island_first_body.size(); ++k) ctx.island_first_body[k] += ctx.island_first_body[k - 1];
  for (std::int32_t& first : ctx.island_first_body) ++first;  // index 0 is the world
  ctx.dynamic_count = ctx.island_first_body.back() - 1;
  ctx.solver_count = 1 + ctx.dynamic_count + static_cast<int>(ctx.kinematic_bodies.size());
  ctx.solver_of_body.assign(n, ctx.static_index);
  ctx.body_of_solver.assign(static_cast<size_t>(ctx.solver_count), -1);
  ctx.island_fill.assign(ctx.island_first_body.begin(), ctx.island_first_body.end() - 1);
  const auto place = [&](size_t i, std::int32_t si) {
    ctx.solver_of_body[i] = si;
    ctx.body_of_solver[static_cast<size_t>(si)] = static_cast<std::int32_t>(i);
  };
  for (size_t i = 0; i < n; ++i)
    if (ctx.body_island[i] >= 0) place(i, ctx.island_fill[static_cast<size_t>(ctx.body_island[i])]++);
  std::int32_t next_kinematic = 1 + ctx.dynamic_count;
  for (const std::int32_t i : ctx.kinematic_bodies) place(static_cast<size_t>(i), next_kinematic++);
  ctx.velocities.resize(static_cast<size_t>(ctx.solver_count));
  ctx.pseudo.resize(ctx.velocities.size());
}

namespace {

// Whether an island's constraints are solved this substep (no guard has
// stopped it), and whether by PGS, in the constraint graph.
bool liveIsland(const StepContext& ctx, std::int32_t isl) {
  return isl >= 0 && !ctx.frozen_island[static_cast<size_t>(isl)];
}
bool pgsIsland(const StepContext& ctx, std::int32_t isl) {
  return ctx.island_method[static_cast<size_t>(isl)] == SolverMethod::PGS;
}

// A layout kept for another (sub)step: its row groups are built again at
// the new pose (prepareConstraints), and the schedules planned on it are
// kept only with `keep_plans` (a group's bodies are read from its rows).
void keepLayout(GraphProblem& g, bool keep_plans) {
  g.rows.clear();
  g.correction_swept = false;
  if (!keep_plans) {
    g.flow.reset();
    g.pipeline.reset();
  }
}

// Steps 1 to 6 of the preparation: which constraints the graph holds, their
// order and colours, and where each goes (a row group or a batch lane).
// What they read (the islands, the contacts, the joints) is fixed for the
// step unless a guard stops an island or a joint breaks, so later substeps
// keep it (prepareConstraints).
//
// Everything after step 2 is a function of the items (their kinds,
// constraints, solver bodies and islands, in order), the counts of dynamic
// bodies and islands, the threads and the order setting: while those are
// the same as when the layout was made, it is kept, and so are the flow
// schedule and the pipeline planned on it where the graph has no row
// groups (a group's bodies are read from its rows, which each substep
// builds anew: a joint may have none at one pose and some at the next). A
// resting stack's graph does not change from step to step (the 5,050-box
// pyramid's first 40 steps: layout and plan 1.2 ms a step on two threads).
void layoutGraph(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  GraphProblem& g = ctx.graph;

  // 1. The island of every joint and contact.
  ctx.joint_island.assign(w.joints_.size(), -1);
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    const Joint& j = w.joints_[i];
    if (j.alive && !j.broken) ctx.joint_island[i] = islandOf(ctx, j.def.body_a, j.def.body_b);
  }
  ctx.contact_island.assign(w.contacts_.size(), -1);
  if (ctx.island_count > 0)  // else every body is asleep or static: no contact has an island
    for (size_t i = 0; i < w.contacts_.size(); ++i) {
      const Contact& c = w.contacts_[i];
      if (c.enabled && c.count > 0) ctx.contact_island[i] = islandOf(ctx, c.body_a, c.body_b);
    }

  // 2. The PGS islands' constraints, and each dynamic body's level: its
  // distance, in constraints, from a static or kinematic body (breadth
  // first from the bodies that touch one; a floating island from its first
  // body).
  std::vector<Item>& items = ctx.items;
  items.clear();
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    const std::int32_t isl = ctx.joint_island[i];
    if (!liveIsland(ctx, isl) || !pgsIsland(ctx, isl)) continue;
    const Joint& j = w.joints_[i];
    items.push_back({Item::JointGroup, static_cast<std::int32_t>(i), solverIndex(ctx, j.def.body_a),
                     solverIndex(ctx, j.def.body_b), isl});
  }
  for (size_t i = 0; i < w.contacts_.size(); ++i) {
    const std::int32_t isl = ctx.contact_island[i];
    if (!liveIsland(ctx, isl) || !pgsIsland(ctx, isl)) continue;
    const Contact& c = w.contacts_[i];
    const Item::Kind kind = usesRowGroup(c) ? Item::ContactGroup : Item::Manifold;
    items.push_back({kind, static_cast<std::int32_t>(i), solverIndex(ctx, c.body_a),
                     solverIndex(ctx, c.body_b), isl});
  }
  const int threads = w.pool_ ? w.pool_->threads() : 1;
  StepContext::LayoutInputs& made = ctx.layout_inputs;
  if (g.laid_out && made.dynamic_count == ctx.dynamic_count && made.island_count == ctx.island_count &&
      made.threads == threads && made.randomize_order == s.randomize_order && made.items == items) {
    keepLayout(g, g.groups.empty());
    return;
  }
  g.clear();
  g.island_count = ctx.island_count;
  ctx.lane_contact.clear();
  ctx.group_joint.clear();
  made.items = items;
  made.dynamic_count = ctx.dynamic_count;
  made.island_count = ctx.island_count;
  made.threads = threads;
  made.randomize_order = s.randomize_order;
  ++made.made;

  const std::int32_t dyn = ctx.dynamic_count + 1;  // the solver indices below this, but 0, are dynamic
  const auto isDyn = [&](std::int32_t si) { return si > 0 && si < dyn; };

  // Adjacency in compressed rows over the dynamic solver bodies.
  std::vector<std::int32_t>&adj_start = ctx.adj_start, &adj = ctx.adj, &level = ctx.level, &queue = ctx.queue;
  adj_start.assign(static_cast<size_t>(dyn) + 1, 0);
  for (const Item& it : items)
    if (isDyn(it.a) && isDyn(it.b)) {
      ++adj_start[static_cast<size_t>(it.a) + 1];
      ++adj_start[static_cast<size_t>(it.b) + 1];
    }
  for (size_t k = 1; k < adj_start.size(); ++k) adj_start[k] += adj_start[k - 1];
  adj.resize(static_cast<size_t>(adj_start.back()));
  ctx.island_fill.assign(adj_start.begin(), adj_start.end() - 1);
  for (const Item& it : items)
    if (isDyn(it.a) && isDyn(it.b)) {
      adj[static_cast<size_t>(ctx.island_fill[static_cast<size_t>(it.a)]++)] = it.b;
      adj[static_cast<size_t>(ctx.island_fill[static_cast<size_t>(it.b)]++)] = it.a;
    }
  level.assign(static_cast<size_t>(dyn), -1);
  queue.clear();
  for (const Item& it : items) {  // grounded bodies first
    const bool a_dyn = isDyn(it.a), b_dyn = isDyn(it.b);
    if (a_dyn == b_dyn) continue;
    const std::int32_t d = a_dyn ? it.a : it.b;
    if (level[static_cast<size_t>(d)] < 0) {
      level[static_cast<size_t>(d)] = 0;
      queue.push_back(d);
    }
  }
  const auto bfs = [&](size_t head) {
    for (; head < queue.size(); ++head) {
      const std::int32_t u = queue[head];
      for (std::int32_t k = adj_start[static_cast<size_t>(u)]; k < adj_start[static_cast<size_t>(u) + 1]; ++k) {
        const std::int32_t v = adj[static_cast<size_t>(k)];
        if (level[static_cast<size_t>(v)] < 0) {
          level[static_cast<size_t>(v)] = level[static_cast<size_t>(u)] + 1;
          queue.push_back(v);
        }
      }
    }
    return head;
  };
  size_t head = bfs(0);
  for (std::int32_t si = 1; si < dyn; ++si)  // floating islands
    if (level[static_cast<size_t>(si)] < 0) {
      level[static_cast<size_t>(si)] = 0;
      queue.push_back(si);
      head = bfs(head);
    }

  // 3. Parts: with a worker pool, the islands in as many contiguous runs as
  // there are threads, of about equal numbers of constraints, each swept
  // by one thread from start to end with no barrier between its colours
  // (graph_solver.hpp). Each colour otherwise ends at a barrier of both
  // threads, a microsecond or so on this machine: pile-1000's ten colours
  // met at 400 barriers a step. One island holding most of the work (a
  // pyramid, a column) keeps the one part whose colours the threads split.
  int parts = 1;
  std::vector<std::int32_t>& island_part = ctx.island_part;
  if (threads > 1 && !s.randomize_order && static_cast<int>(items.size()) >= kParallelPartItems) {
    std::vector<std::int32_t>& work = ctx.island_work;
    work.assign(static_cast<size_t>(ctx.island_count), 0);
    for (const Item& it : items) ++work[static_cast<size_t>(it.island)];
    const auto total = static_cast<std::int64_t>(items.size());
    g.part_island.assign(static_cast<size_t>(threads) + 1, ctx.island_count);
    g.part_island[0] = 0;
    std::int64_t done = 0, part_start = 0, largest = 0;  // constraints so far, at the part's start, in the largest part
    int next = 1;
    for (std::int32_t isl = 0; isl < ctx.island_count; ++isl) {
      done += work[static_cast<size_t>(isl)];
      while (next < threads && done * threads >= total * next) {
        g.part_island[static_cast<size_t>(next++)] = isl + 1;
        largest = std::max(largest, done - part_start);
        part_start = done;
      }
    }
    largest = std::max(largest, total - part_start);
    // At most a fifth over an even share: else the longest part would
    // keep the other threads waiting longer than the barriers cost.
    if (largest * threads * 5 <= total * 6) {
      parts = threads;
      island_part.assign(static_cast<size_t>(ctx.island_count), 0);
      for (int k = 0; k < parts; ++k)
        for (std::int32_t isl = g.part_island[static_cast<size_t>(k)]; isl < g.part_island[static_cast<size_t>(k) + 1]; ++isl)
          island_part[static_cast<size_t>(isl)] = k;
    } else {
      g.part_island.clear();
    }
  }

  // 4. Sort by part, then level (joints before contacts within a level,
  // then creation order: `items` is in that order already, so a stable
  // counting sort). An island's constraints keep their order whatever the
  // parts: its levels come one after another in its own part.
  const auto itemLevel = [&](const Item& it) {
    const std::int32_t la = isDyn(it.a) ? level[static_cast<size_t>(it.a)] : 0;
    const std::int32_t lb = isDyn(it.b) ? level[static_cast<size_t>(it.b)] : 0;
    const bool lateral = isDyn(it.a) && isDyn(it.b) && la == lb;
    return 2 * std::max(la, lb) + (lateral ? 1 : 0);
  };
  std::vector<Item>& sorted = ctx.sorted_items;
  std::vector<std::int32_t>& level_start = ctx.level_start;
  std::int32_t max_level = 0;
  for (const Item& it : items) max_level = std::max(max_level, itemLevel(it));
  const std::int32_t levels = max_level + 1;  // per part
  const auto itemKey = [&](const Item& it) {
    return (parts > 1 ? island_part[static_cast<size_t>(it.island)] * levels : 0) + itemLevel(it);
  };
  level_start.assign(static_cast<size_t>(parts * levels) + 1, 0);
  for (const Item& it : items) ++level_start[static_cast<size_t>(itemKey(it)) + 1];
  for (size_t k = 1; k < level_start.size(); ++k) level_start[k] += level_start[k - 1];
  sorted.resize(items.size());
  for (const Item& it : items) sorted[static_cast<size_t>(level_start[static_cast<size_t>(itemKey(it))]++)] = it;

  // 5. Colours: level by level, each level's constraints coloured greedily
  // (the lowest of the level's colours in which neither dynamic body has a
  // constraint yet), the levels' colours one after another; a part's
  // colours after those of the part before.
  std::vector<std::uint64_t>& used = ctx.colour_used;
  used.assign(static_cast<size_t>(dyn), 0);
  ctx.colour_of.resize(sorted.size());
  std::int32_t colours = 0;
  if (parts > 1) g.part_colour.assign(static_cast<size_t>(parts) + 1, 0);
  for (size_t lv = 0; lv + 1 < level_start.size(); ++lv) {
    if (parts > 1 && lv % static_cast<size_t>(levels) == 0) g.part_colour[lv / static_cast<size_t>(levels)] = colours;
    const std::int32_t first = lv == 0 ? 0 : level_start[lv - 1];
    const std::int32_t last = level_start[lv];
    std::int32_t level_colours = 0;
    for (std::int32_t k = first; k < last; ++k) {
      const Item& it = sorted[static_cast<size_t>(k)];
      std::uint64_t mask = 0;
      if (isDyn(it.a)) mask |= used[static_cast<size_t>(it.a)];
      if (isDyn(it.b)) mask |= used[static_cast<size_t>(it.b)];
      // 64 colours in one level would take 64 constraints on one body: past
      // that, the rest of the level goes one colour each after them.
      int free = mask == ~std::uint64_t(0) ? 64 + (k - first) : std::countr_one(mask);
      if (free < 64) {
        if (isDyn(it.a)) used[static_cast<size_t>(it.a)] |= std::uint64_t(1) << free;
        if (isDyn(it.b)) used[static_cast<size_t>(it.b)] |= std::uint64_t(1) << free;
      }
      ctx.colour_of[static_cast<size_t>(k)] = colours + free;
      level_colours = std::max(level_colours, free + 1);
    }
    for (std::int32_t k = first; k < last; ++k) {  // clear the level's marks
      const Item& it = sorted[static_cast<size_t>(k)];
      if (isDyn(it.a)) used[static_cast<size_t>(it.a)] = 0;
      if (isDyn(it.b)) used[static_cast<size_t>(it.b)] = 0;
    }
    colours += level_colours;
  }
  if (parts > 1) g.part_colour[static_cast<size_t>(parts)] = colours;

  // 6. Layout: per colour its row groups, then its manifolds in batches of 8.
  std::vector<std::int32_t>&groups_in = ctx.groups_in, &manifolds_in = ctx.manifolds_in;
  groups_in.assign(static_cast<size_t>(colours), 0);
  manifolds_in.assign(static_cast<size_t>(colours), 0);
  for (size_t k = 0; k < sorted.size(); ++k)
    (sorted[k].kind == Item::Manifold ? manifolds_in : groups_in)[static_cast<size_t>(ctx.colour_of[k])]++;
  g.colours.resize(static_cast<size_t>(colours));
  std::int32_t batch_at = 0, group_at = 0;
  for (std::int32_t c = 0; c < colours; ++c) {
    GraphColour& gc = g.colours[static_cast<size_t>(c)];
    gc.group_begin = group_at;
    group_at += groups_in[static_cast<size_t>(c)];
    gc.group_end = group_at;
    gc.batch_begin = batch_at;
    batch_at += (manifolds_in[static_cast<size_t>(c)] + kBatchLanes - 1) / kBatchLanes;
    gc.batch_end = batch_at;
  }
  resizeGrowing(g.batches, static_cast<size_t>(batch_at));
  resizeGrowing(g.groups, static_cast<size_t>(group_at));
  assignGrowing(ctx.group_joint, static_cast<size_t>(group_at), 0);
  // Each manifold's lane, in level order within its colour.
  assignGrowing(ctx.lane_contact, static_cast<size_t>(batch_at) * kBatchLanes, -1);
  std::vector<std::int32_t>& lane_fill = ctx.lane_fill;
  lane_fill.resize(static_cast<size_t>(colours));
  for (std::int32_t c = 0; c < colours; ++c) lane_fill[static_cast<size_t>(c)] = g.colours[static_cast<size_t>(c)].batch_begin * kBatchLanes;
  for (size_t k = 0; k < sorted.size(); ++k) {
    const Item& it = sorted[k];
    if (it.kind != Item::Manifold) continue;
    const std::int32_t slot = lane_fill[static_cast<size_t>(ctx.colour_of[k])]++;
    ctx.lane_contact[static_cast<size_t>(slot)] = it.index;
    g.batches[static_cast<size_t>(slot / kBatchLanes)].island[slot % kBatchLanes] = it.island;
  }
  g.laid_out = true;
}

}  // namespace

void prepareConstraints(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  const Real h = ctx.hs;
  const bool first_substep = ctx.substep == 0;

  // The solver bodies' velocities, from the bodies.
  for (std::int32_t si = 1; si < ctx.solver_count; ++si) {
    const Body& b = w.bodies_[static_cast<size_t>(ctx.body_of_solver[static_cast<size_t>(si)])];
    ctx.velocities[static_cast<size_t>(si)] = SolverBody{b.linear_velocity, b.angular_velocity};
  }
  ctx.velocities[static_cast<size_t>(ctx.static_index)] = SolverBody{};

  // Later substeps keep the first's layout and, unless every substep is
  // to prepare its contacts anew, its contact lanes, whose separations and
  // targets the refresh kernel makes again at the present poses
  // (SolverSettings::prepare_contacts_each_substep). Both are made again
  // if a guard has stopped an island or a joint has broken since.
  const bool same_graph = !first_substep && !ctx.any_frozen && w.break_events_.empty();
  const bool refresh_lanes = same_graph && !s.prepare_contacts_each_substep;
  const bool last_substep = ctx.substep + 1 == s.substeps;
  GraphProblem& g = ctx.graph;
  // Refreshed lanes carry their impulses from substep to substep, ahead of
  // the contact cache (storeImpulses); lanes about to be prepared anew read
  // the cache, so it catches up first. (At a step's first substep nothing
  // is ahead: the lanes left by a step that threw may name contacts that
  // are gone.)
  if (first_substep) {
    ctx.lanes_unstored = false;
  } else if (ctx.lanes_unstored &&
             (!refresh_lanes || (last_substep && std::any_of(g.batches.begin(), g.batches.end(), anyBounce)))) {
    storeLaneImpulses(w, ctx);
  }
  if (same_graph) {
    keepLayout(g, false);
  } else {
    layoutGraph(w, ctx);
  }
  ctx.rows.clear();
  ctx.island_rows.assign(static_cast<size_t>(ctx.island_count), {0, 0});
  for (int& k : w.stats_.rows_by_kind) k = 0;
  const std::vector<Item>& sorted = ctx.sorted_items;
  const auto colours = static_cast<std::int32_t>(g.colours.size());

  // 7. Fill.
  const Correction correction = s.split_impulse ? Correction::PseudoVelocity : s.position_correction;
  ContactFillParams fp;
  fp.h = h;
  fp.cfm = s.cfm / h;
  fp.contact_erp = s.contact_erp;
  fp.slop = s.slop;
  fp.threshold = s.restitution_threshold;
  fp.max_correction = s.max_correction_velocity;
  fp.warm = s.warm_start ? s.warm_start_factor : Real(0);
  fp.in_rhs = correction == Correction::InRhs;
  fp.first_substep = first_substep;
  fp.friction_rows = s.friction_directions;
  fp.patch = s.patch_friction;
  const ContactKernels& kernels = contactKernelsFor(s);
  ContactRowSettings crs;
  crs.h = h;
  crs.contact_erp = s.contact_erp;
  crs.cfm = s.cfm;
  crs.slop = s.slop;
  crs.restitution_threshold = s.restitution_threshold;
  crs.max_correction_velocity = s.max_correction_velocity;
  crs.correction = correction;
  crs.warm_start = s.warm_start;
  crs.warm_start_factor = s.warm_start_factor;
  crs.friction_directions = s.friction_directions;
  const JointRowSettings jrs{s.restitution_threshold};
  const auto jointRows = [&](std::int32_t ji, std::vector<ConstraintRow>& rows, Correction correction) {
    const Joint& j = w.joints_[static_cast<size_t>(ji)];
    RowContext rc;
    rc.h = h;
    rc.erp = s.erp;
    rc.cfm = s.cfm;
    rc.joint_softness = &j.def.softness;
    rc.owner = ji;
    rc.rows = &rows;
    rc.warm = s.warm_start ? &j.warm : nullptr;
    rc.warm_factor = s.warm_start_factor;
    rc.max_correction_velocity = s.max_correction_velocity;
    rc.correction = correction;
    buildJointRows(j, solverView(w, ctx, j.def.body_a), solverView(w, ctx, j.def.body_b), rc, jrs);
  };
  ctx.island_pushing.assign(static_cast<size_t>(ctx.island_count), 0);

  // The row groups, at this substep's pose (the manifolds have their lanes
  // from layoutGraph, and are filled below).
  std::vector<std::int32_t>& group_fill = ctx.group_fill;
  group_fill.resize(static_cast<size_t>(colours));
  for (std::int32_t c = 0; c < colours; ++c) group_fill[static_cast<size_t>(c)] = g.colours[static_cast<size_t>(c)].group_begin;
  for (size_t k = 0; k < sorted.size(); ++k) {
    const Item& it = sorted[k];
    if (it.kind == Item::Manifold) continue;
    const size_t c = static_cast<size_t>(ctx.colour_of[k]);
    const std::int32_t gi = group_fill[c]++;
    RowGroup& grp = g.groups[static_cast<size_t>(gi)];
    grp.begin = static_cast<std::int32_t>(g.rows.size());
    grp.island = it.island;
    if (it.kind == Item::JointGroup) {
      ctx.group_joint[static_cast<size_t>(gi)] = it.index;
      jointRows(it.index, g.rows, s.position_correction);
    } else {
      ctx.group_joint[static_cast<size_t>(gi)] = -1 - it.index;
      Contact& con = w.contacts_[static_cast<size_t>(it.index)];
      const BodyView a = solverView(w, ctx, con.body_a), b = solverView(w, ctx, con.body_b);
      buildContactNormalRows(con, it.index, a, b, crs, g.rows);
      buildContactFrictionRows(con, it.index, a, b, crs, grp.begin, g.rows);
    }
    grp.end = static_cast<std::int32_t>(g.rows.size());
    for (std::int32_t r = grp.begin; r < grp.end; ++r)
      if (g.rows[static_cast<size_t>(r)].bias_rhs > 0) ctx.island_pushing[static_cast<size_t>(it.island)] = 1;
  }
  // The lanes in storage order, a batch's eight one after another: a batch
  // is 11.5 KB, a cache line per field, and filling its lanes at eight
  // different times (in the level order above) brought it into the cache
  // eight times, which made this loop a fifth of an awake pyramid's step.
  // Each batch is filled and factored on its own, so the batches are split
  // among the pool's threads when there are enough of them (a batch is
  // about a microsecond of work, as much as handing a loop over).
  // Each batch's manifolds and bodies are gathered lane by lane into one
  // input (6.7 KB, on the thread's stack: it stays in the cache), which the
  // fill kernel turns into the lanes W at a time (AVX-512: the eight at
  // once, where a lane alone was a sixth of an awake pyramid's step).
  const auto fillBatch = [&](ContactBatchInput& in, ContactBatch& batch, int bi) {
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      const std::int32_t ci = ctx.lane_contact[static_cast<size_t>(bi) * kBatchLanes + static_cast<size_t>(lane)];
      if (ci < 0) {
        gatherLane(in, batch, lane, kPadding, 0, 0, 0, w);  // the world on both sides, solver slot 0
        continue;
      }
      const Contact& con = w.contacts_[static_cast<size_t>(ci)];
      gatherLane(in, batch, lane, con, solverIndex(ctx, con.body_a), solverIndex(ctx, con.body_b), batch.island[lane], w);
    }
    kernels.fill(batch, in, fp);
    factorBatch(batch);
    invertRowMasses(batch);
  };
  // A later substep refreshes the lanes instead: their poses gathered (the
  // padding lanes' as the world's) and the separations made again. Except
  // on the last substep, for a batch with a point that bounces: the
  // restitution pass after it drives that point's normal velocity to the
  // bounce, and along anchors a substep or more old a spinning body left
  // the bounce with more energy than it brought (a box at restitution 1,
  // 0.2 to 0.5%, tests/unit/restitution_energy_test.cpp). Without a bounce
  // target a visit only removes energy, whatever its Jacobian.
  const auto refreshBatch = [&](ContactBatchInput& in, ContactBatch& batch, int bi) {
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      const std::int32_t ci = ctx.lane_contact[static_cast<size_t>(bi) * kBatchLanes + static_cast<size_t>(lane)];
      gatherPoses(in, lane, ci < 0 ? kPadding : w.contacts_[static_cast<size_t>(ci)], w);
    }
    kernels.refresh(batch, in, fp);
  };
  // Right after its fill, while the batch is in the cache, its rows by kind
  // (statistics: each valid point a normal row and, with friction, one or
  // two tangent rows; a patch's twist row) and, per lane, the island it
  // pushes out (a correction target above zero is a push; padding and
  // InRhs lanes have none) or -1. A walk over the batches after the fill
  // read them from memory again, on the calling thread alone: 0.5 ms a
  // step of the 5,050-box pyramid (docs/performance.md).
  const int batch_count = static_cast<int>(g.batches.size());
  ctx.lane_pushing.resize(static_cast<size_t>(batch_count) * kBatchLanes);
  std::atomic<int> normal_rows{0}, friction_rows{0};
  const auto tallyBatch = [&](const ContactBatch& batch, int bi, int& normal, int& friction) {
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      friction += batch.twist_mass[lane] > 0;
      bool push = false;
      for (int i = 0; i < batch.count[lane]; ++i) {
        push = push || batch.p[i].bias[lane] > 0;
        if (batch.p[i].valid[lane] > 0) {
          ++normal;
          if (batch.mu[lane] > 0)
            for (int k = 0; k < 2; ++k) friction += batch.p[i].tangent_mass[k][lane] > 0;
        }
      }
      ctx.lane_pushing[static_cast<size_t>(bi) * kBatchLanes + static_cast<size_t>(lane)] = push ? batch.island[lane] : -1;
    }
  };
  const auto fillBatches = [&](int begin, int end) {
    ContactBatchInput in;
    int normal = 0, friction = 0;
    for (int bi = begin; bi < end; ++bi) {
      if (bi + 1 < end)  // the next batch's contacts, while this one is gathered (step_solve.cpp's store does the same)
        for (int lane = 0; lane < kBatchLanes; ++lane)
          prefetchLaneContact(w, ctx, static_cast<size_t>(bi + 1) * kBatchLanes + static_cast<size_t>(lane));
      ContactBatch& batch = g.batches[static_cast<size_t>(bi)];
      if (refresh_lanes && !(last_substep && anyBounce(batch))) refreshBatch(in, batch, bi);
      else fillBatch(in, batch, bi);
      tallyBatch(batch, bi, normal, friction);
    }
    normal_rows += normal;  // sums of counts: the same whatever the split
    friction_rows += friction;
  };
  if (w.pool_ && batch_count >= kParallelBatches) w.pool_->parallelFor(batch_count, fillBatches);
  else fillBatches(0, batch_count);
  for (const std::int32_t isl : ctx.lane_pushing)
    if (isl >= 0) ctx.island_pushing[static_cast<size_t>(isl)] = 1;

  // 8. The other islands: generic rows island by island, joints first, then
  // all contact normal rows before any friction row (ODE's and Bullet's
  // order). The direct and exact solvers solve the ERP target with the rest
  // in one exact solve, so joints keep it in rhs.
  ctx.island_start.assign(static_cast<size_t>(ctx.island_count) + 1, 0);
  bool any_other = false;
  for (std::int32_t isl = 0; isl < ctx.island_count; ++isl) any_other = any_other || (liveIsland(ctx, isl) && !pgsIsland(ctx, isl));
  if (any_other) {
    for (std::int32_t isl = 0; isl < ctx.island_count; ++isl) {
      if (!liveIsland(ctx, isl) || pgsIsland(ctx, isl)) continue;
      const auto begin = static_cast<std::int32_t>(ctx.rows.size());
      for (size_t i = 0; i < w.joints_.size(); ++i)
        if (ctx.joint_island[i] == isl) jointRows(static_cast<std::int32_t>(i), ctx.rows, Correction::InRhs);
      for (size_t i = 0; i < w.contacts_.size(); ++i)
        if (ctx.contact_island[i] == isl) {
          Contact& con = w.contacts_[i];
          buildContactNormalRows(con, static_cast<std::int32_t>(i), solverView(w, ctx, con.body_a),
                                 solverView(w, ctx, con.body_b), crs, ctx.rows);
        }
      for (size_t i = 0; i < w.contacts_.size(); ++i)
        if (ctx.contact_island[i] == isl) {
          Contact& con = w.contacts_[i];
          buildContactFrictionRows(con, static_cast<std::int32_t>(i), solverView(w, ctx, con.body_a),
                                   solverView(w, ctx, con.body_b), crs, begin, ctx.rows);
        }
      ctx.island_rows[static_cast<size_t>(isl)] = {begin, static_cast<std::int32_t>(ctx.rows.size())};
      for (std::int32_t r = begin; r < static_cast<std::int32_t>(ctx.rows.size()); ++r)
        if (ctx.rows[static_cast<size_t>(r)].bias_rhs > 0) ctx.island_pushing[static_cast<size_t>(isl)] = 1;
    }
  }

  // Rows by kind (statistics): the generic rows', and the batches' counted
  // after their fill (a patch: two tangent rows at point 0 and the twist
  // row, all friction).
  int* kinds = w.stats_.rows_by_kind;
  for (const ConstraintRow& r : g.rows) ++kinds[static_cast<int>(r.kind)];
  for (const ConstraintRow& r : ctx.rows) ++kinds[static_cast<int>(r.kind)];
  kinds[static_cast<int>(RowKind::ContactNormal)] += normal_rows.load();
  kinds[static_cast<int>(RowKind::ContactFriction)] += friction_rows.load();
  int total = 0;
  for (int k = 0; k < kRowKindCount; ++k) total += kinds[k];
  w.stats_.rows = total;
}

}  // namespace cairn::detail
