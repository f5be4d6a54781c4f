// The step's watchers: what goes wrong without a NaN, reported in
// World::diagnostics (one record per body and kind, counting the steps it
// happened in) and by `cairn run` on stderr and in the metrics.
//
//   energy rise       the total energy E = T + V (kinetic, gravity, springs)
//                     grew without external work. Per step
//                       dE = E(end) - E(start),
//                     both from the same bodies (ctx.step_start holds the
//                     state the step began from, after any change made
//                     through the API, so a teleport or a new body is not
//                     counted). The rise is the growth since the lowest
//                     point of a stretch of steps without external work:
//                       rise = max(0, rise + dE),
//                     reset by any step with external work (constant
//                     forces, forces applied through the API, timed
//                     impulses, motors, moving kinematic bodies). Reported
//                     when rise > energy_rise * S, with the energy scale
//                       S = T + V_springs + sum_i m_i |g| L_i,
//                     L_i = sqrt(tr J_i / (2 m_i)) the body's radius of
//                     gyration: the energy in motion and in springs, and
//                     the work to lift every body by its own size.
//                     A push-out of a penetration of a few mm, or a joint's
//                     Baumgarte correction, stays far below it; an
//                     integrator or solver that feeds energy in does not.
//   joint drift       a joint's anchors apart by more than joint_drift, or
//                     its angle error beyond joint_drift_angle.
//   penetration       a contact deeper than slop + penetration_drift after
//                     the step: a stack sinking or a contact not resolved.
//   stack sinking     a stack of resting bodies sunk into itself by more
//                     than slop + penetration_drift. A contact may rest up
//                     to the slop deep, where no push-out acts, so that
//                     depth stays for good; a solve that does not carry a
//                     tall stack's weight through every contact (PGS: an
//                     impulse crosses N contacts in about N^2 sweeps) lets
//                     each of them sink so, and the top sinks by their sum:
//                     50 boxes by 15 cm with no contact deeper than 6 mm,
//                     which the penetration watcher cannot see. With
//                     up = -g/|g|, a touching contact whose normal is
//                     within 45 degrees of up, between a body and one
//                     whose centre is lower, holds the upper body on the
//                     lower one (on nothing that sinks if the lower is
//                     static or kinematic):
//                       sunk(upper) = max over those contacts of
//                                     sunk(lower) + (depth if depth <= slop, else 0),
//                     the deepest path down to the ground, found by
//                     relaxing the contacts until nothing changes, forward
//                     and backward in turn (a column listed bottom up or
//                     top down takes one pass and one to confirm; heights
//                     fall strictly along a path, so there is no cycle).
//                     A contact deeper than the slop adds nothing: the
//                     push-out removes contact_erp of
//                     its excess a step, a transient (a landing pile) that
//                     the penetration watcher reports when it is deep.
//                     Reported on the top body of each sunk stack.
//   fast body without CCD
//                     a body without continuous collision moved, in one
//                     step, further than its own thickness plus that of a
//                     shape its path overlaps and that it collides with
//                     (filter bits, joints): it can pass through that
//                     shape without ever touching it (the classic
//                     tunnelling of discrete collision: Ericson, "Real-Time
//                     Collision Detection", section 9.5; Bullet and Jolt
//                     offer CCD for the same reason).
//   exact solve too large
//                     an island with method lcp over max_exact_rows rows,
//                     solved by PGS instead that step (world/islands.cpp).
//   contact pairs capped
//                     a shape overlapped more than max_pairs_per_shape
//                     others; the rest were not tested that step
//                     (collision/broadphase.hpp).
//
// Each watcher reads what the step left behind and changes nothing in the
// simulation: a World with the watchers' settings at infinity steps bit for
// bit as one with their defaults.
#include "collision/aabb.hpp"
#include "constraints/parts.hpp"
#include "dynamics/forces.hpp"
#include "world/body_walk.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/step_stages.hpp"

#include <algorithm>
#include <cmath>
#include <charconv>

namespace cairn::detail {

namespace {

// Three significant digits, as a stream with precision 3 prints them, but
// without a stream: a watcher that fires every step (a whipping chain's
// joint drift) formats its figures every step, and a stream's construction
// (locale facets) cost more than the rest of the watcher.
std::string fmt(Real v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 3);
  return std::string(buf, r.ptr);
}

Real springEnergyAt(const WorldImpl& w, const Spring& s, const StepContext* start) {
  const auto point = [&](BodyId id, const Vec3& local) {
    if (id.isWorld()) return local;
    if (!start) return w.body(id).transform().apply(local);
    const StepContext::SavedState& st = start->step_start[static_cast<size_t>(id.index)];
    return Transform{st.x, st.q}.apply(local);
  };
  return springEnergy((point(s.def.body_b, s.local_b) - point(s.def.body_a, s.local_a)).norm(), s.rest_length,
                      s.def.stiffness);
}

// Whether a body can have moved in this step (the world cannot).
bool movedInStep(const StepContext& ctx, BodyId id) { return !id.isWorld() && ctx.moves(static_cast<size_t>(id.index)); }

// Whether anything outside the bodies did work on them this step. A body
// pushed so (a constant force, a timed impulse) was woken by it, and a
// kinematic body always moves in the step: only those can have.
bool externalWork(const WorldImpl& w, const StepContext& ctx) {
  if (w.external_forces_) return true;
  for (size_t i = 0; i < w.bodies_.size(); ++i) {
    if (!ctx.moves(i)) continue;
    const Body& b = w.bodies_[i];
    if (!b.alive) continue;
    if (b.type == BodyType::Kinematic && b.linear_velocity.squaredNorm() + b.angular_velocity.squaredNorm() > 0)
      return true;
    if (!b.isDynamic()) continue;
    if (b.constant_force != Vec3::Zero() || b.constant_torque != Vec3::Zero()) return true;
    // A timed impulse applied at this step's start (world/step_integrate.cpp).
    if (b.next_impulse > 0 && b.impulses[b.next_impulse - 1].time > w.time_ - ctx.h) return true;
  }
  for (const Joint& j : w.joints_)
    if (j.alive && !j.broken && (j.def.motor.enabled || !j.def.motor_axes.empty())) return true;
  return false;
}

// E = T + V at the step's start and end, in one pass in body order. The
// bodies that moved (StepContext::moves) are summed at both ends (their
// start from ctx.start_energy); the others, whose energy did not change,
// once, from ctx.start_energy: a sleeping body is not read at all.
void watchEnergy(WorldImpl& w, StepContext& ctx) {
  const bool watch = !externalWork(w, ctx);
  Real before = 0, after = 0, still = 0, scale = 0;
  if (watch)
    for (const Spring& s : w.springs_)
      if (s.alive) scale += springEnergyAt(w, s, nullptr);
  const Real g = w.gravity_.norm();
  // Each moving dynamic body's T + V now and its share of the energy scale
  // (what is in motion, and the work to lift each awake body by its radius
  // of gyration), on the pool's threads (world/body_walk.hpp); summed below
  // in body order on this thread, from these arrays.
  const size_t n = w.bodies_.size();
  ctx.end_energy.resize(n);
  ctx.energy_scale.resize(n);
  ctx.energy_counted.resize(n);
  anyBody(w, [&](size_t i) {
    const Body& b = w.bodies_[i];
    const bool counted = ctx.moves(i) && b.alive && b.isDynamic();
    ctx.energy_counted[i] = counted;
    if (!counted) return false;
    const Real kinetic = b.kineticEnergy();
    ctx.end_energy[i] = kinetic - b.mass * w.gravity_.dot(b.position);
    ctx.energy_scale[i] = watch && !b.asleep
                              ? kinetic + b.mass * g * std::sqrt(std::max(Real(0), b.inertia_body.trace() / (2 * b.mass)))
                              : Real(0);
    return false;
  });
  for (size_t i = 0; i < n; ++i) {
    if (!ctx.moves(i)) {
      still += ctx.start_energy[i];  // 0 for a body that is not dynamic
      continue;
    }
    if (!ctx.energy_counted[i]) continue;
    before += ctx.start_energy[i];
    after += ctx.end_energy[i];
    scale += ctx.energy_scale[i];  // + 0 for a body asleep or not watched
  }
  for (const Spring& s : w.springs_)
    if (s.alive) {
      before += springEnergyAt(w, s, &ctx);
      after += springEnergyAt(w, s, nullptr);
    }
  w.stats_.energy = after + still;
  if (!std::isfinite(before) || !std::isfinite(after)) return;  // the guard reports non-finite states
  if (!watch) {
    w.energy_rise_ = 0;
    return;
  }
  w.energy_rise_ = std::max(Real(0), w.energy_rise_ + (after - before));
  if (!(w.energy_rise_ > w.settings_.energy_rise * scale) || scale <= 0) return;
  w.diagnose(-1, "energy rise",
             "energy rose by " + fmt(w.energy_rise_) + " J without external work (tolerance energy_rise = " +
                 fmt(w.settings_.energy_rise) + " of the energy scale " + fmt(scale) +
                 " J): an unstable integrator, solver or stiffness; try more substeps or a smaller dt", true);
  w.energy_rise_ = 0;
}

void watchJoints(WorldImpl& w) {
  const SolverSettings& s = w.settings_;
  for (size_t i = 0; i < w.joints_.size(); ++i) {
    const Joint& j = w.joints_[i];
    if (!j.alive || j.broken) continue;
    const BodyId a = j.def.body_a, b = j.def.body_b;
    const bool awake = (!a.isWorld() && !w.body(a).asleep && w.body(a).isDynamic()) ||
                       (!b.isWorld() && !w.body(b).asleep && w.body(b).isDynamic());
    if (!awake) continue;
    // A ball joint's error is its anchors' distance, read from the poses
    // (the same numbers worldPoint reads, without two views a joint).
    const auto anchor = [&](BodyId id, const Vec3& local) {
      return id.isWorld() ? local : Vec3(w.body(id).position + w.body(id).orientation * local);
    };
    const JointError e = j.def.type == JointType::Ball
                             ? JointError{(anchor(b, j.local_anchor_b) - anchor(a, j.local_anchor_a)).norm(), 0}
                             : measureJointError(j, w.view(a), w.view(b));
    if (!(e.linear > s.joint_drift) && !(e.angular > s.joint_drift_angle)) continue;
    const BodyId on = b.isWorld() ? a : b;
    w.diagnose(on.index, "joint drift",
               "joint '" + j.def.name + "' apart by " + fmt(e.linear) + " m and " + fmt(e.angular) +
                   " rad (tolerances joint_drift = " + fmt(s.joint_drift) + " m, joint_drift_angle = " +
                   fmt(s.joint_drift_angle) + " rad): more iterations or substeps, or a smaller mass ratio", true);
  }
}

// Contact c as a support of one body on another (the stack watcher), if
// it is one, with the depth it stays sunk by.
void addSupport(const WorldImpl& w, const Contact& c, Real depth, const Vec3& up,
                std::vector<StepContext::Support>& supports) {
  if (!c.touching && !(depth > 0)) return;
  const Real cos45 = std::sqrt(Real(0.5));
  const Real along = c.normal.dot(up);  // the normal points from A to B
  BodyId lower = c.body_a, upper = c.body_b;
  if (along < -cos45) std::swap(lower, upper);
  else if (!(along > cos45)) return;
  if (upper.isWorld() || !w.body(upper).isDynamic() || w.body(upper).asleep) return;
  const bool sinks = !lower.isWorld() && w.body(lower).isDynamic();
  if (sinks && !((w.body(upper).position - w.body(lower).position).dot(up) > 0)) return;
  const Real stays = depth > 0 && depth <= w.settings_.slop ? depth : Real(0);
  supports.push_back({sinks ? lower.index : -1, upper.index, stays});
}

// Returns the deepest overlap of any contact (StepStats::max_penetration):
// one pass over the contacts serves the statistic, the watcher and the
// stack watcher's supports. A contact whose bodies cannot have moved keeps
// the depth it had (and holds up no awake body: no support).
Real watchPenetration(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  const Real tolerance = s.slop + s.penetration_drift;
  const Real g = w.gravity_.norm();
  const Vec3 up = g > 0 ? Vec3(-w.gravity_ / g) : Vec3::Zero();
  // Each contact on its own, on the pool's threads when there are many:
  // its depth, and what the watchers take from it, per thread; then the
  // threads' finds joined in range order, which is the contacts' order
  // whatever the split. With no solver body but the world's nothing moved:
  // every contact is still, its depth kept.
  const bool anything_moved = ctx.solver_count > 1;
  const auto still = [&](const Contact& c) {
    return !anything_moved || (!movedInStep(ctx, c.body_a) && !movedInStep(ctx, c.body_b));
  };
  const int count = static_cast<int>(w.contacts_.size());
  const bool parallel = w.pool_ && anything_moved && count >= kParallelContacts;
  ctx.contact_watch.resize(parallel ? static_cast<size_t>(w.pool_->threads()) : 1);
  for (StepContext::ContactWatch& cw : ctx.contact_watch) {  // a thread given no range leaves its own empty
    cw.supports.clear();
    cw.too_deep.clear();
    cw.contacts = cw.points = 0;
    cw.deepest = 0;
  }
  const auto watchRange = [&](int begin, int end) {
    StepContext::ContactWatch& cw = ctx.contact_watch[parallel ? static_cast<size_t>(WorkerPool::currentThread()) : 0];
    for (int i = begin; i < end; ++i) {
      Contact& c = w.contacts_[static_cast<size_t>(i)];
      if (!c.enabled) continue;
      ++cw.contacts;
      cw.points += c.count;
      if (still(c)) {
        cw.deepest = std::max(cw.deepest, c.depth_after);
        continue;
      }
      const Real depth = c.depth_after = w.contactDepth(c);
      cw.deepest = std::max(cw.deepest, depth);
      if (g > 0) addSupport(w, c, depth, up, cw.supports);
      if (depth > tolerance) cw.too_deep.push_back(i);
    }
  };
  if (parallel) w.pool_->parallelFor(count, watchRange);
  else watchRange(0, count);
  ctx.supports.clear();
  Real deepest = 0;
  for (const StepContext::ContactWatch& cw : ctx.contact_watch) {
    w.stats_.contacts += static_cast<int>(cw.contacts);
    w.stats_.contact_points += static_cast<int>(cw.points);
    deepest = std::max(deepest, cw.deepest);
    ctx.supports.insert(ctx.supports.end(), cw.supports.begin(), cw.supports.end());
    for (const std::int32_t i : cw.too_deep) {
      const Contact& c = w.contacts_[static_cast<size_t>(i)];
      const BodyId dyn = !c.body_b.isWorld() && w.body(c.body_b).isDynamic() ? c.body_b : c.body_a;
      if (dyn.isWorld() || !w.body(dyn).isDynamic() || w.body(dyn).asleep) continue;
      const BodyId other = dyn.index == c.body_a.index ? c.body_b : c.body_a;
      w.diagnose(dyn.index, "penetration",
                 "penetrates '" + (other.isWorld() ? std::string("world") : w.body(other).name) + "' by " +
                     fmt(c.depth_after) + " m (slop " + fmt(s.slop) + " + penetration_drift " +
                     fmt(s.penetration_drift) +
                     " m): a hard impact, a stack sinking or a contact not resolved; more iterations or substeps",
                 true);
    }
  }
  return deepest;
}

void watchStacks(WorldImpl& w, StepContext& ctx) {
  if (ctx.supports.empty()) return;
  const SolverSettings& s = w.settings_;
  const Real tolerance = s.slop + s.penetration_drift;
  std::vector<Real>& sunk = ctx.sunk;
  std::vector<char>& below = ctx.sunk_below;
  sunk.assign(w.bodies_.size(), 0);
  below.assign(w.bodies_.size(), 0);
  // Each pass settles at least one more support of the deepest path; the
  // passes run forward and backward in turn, so a stack listed bottom up or
  // top down settles in one.
  const size_t n = ctx.supports.size();
  for (size_t pass = 0; pass <= n; ++pass) {
    bool changed = false;
    for (size_t k = 0; k < n; ++k) {
      const StepContext::Support& sp = ctx.supports[pass % 2 == 0 ? k : n - 1 - k];
      const Real d = (sp.lower < 0 ? 0 : sunk[static_cast<size_t>(sp.lower)]) + sp.depth;
      Real& u = sunk[static_cast<size_t>(sp.upper)];
      if (d > u) {
        u = d;
        changed = true;
      }
    }
    if (!changed) break;
  }
  Real deepest = 0;
  for (const StepContext::Support& sp : ctx.supports) {
    const Real u = sunk[static_cast<size_t>(sp.upper)];
    deepest = std::max(deepest, u);
    if (u > tolerance && sp.lower >= 0) below[static_cast<size_t>(sp.lower)] = 1;
  }
  if (!(deepest > tolerance)) return;
  for (size_t i = 0; i < sunk.size(); ++i) {
    if (!(sunk[i] > tolerance) || below[i]) continue;
    w.diagnose(static_cast<std::int32_t>(i), "stack sinking",
               "the stack under it has sunk by " + fmt(sunk[i]) +
                   " m, summed over its contacts resting within the slop (slop " + fmt(s.slop) +
                   " + penetration_drift " + fmt(s.penetration_drift) +
                   " m): the solve does not carry the stack's weight; more iterations or substeps", true);
  }
}

// Thickness of a shape: the smallest extent of its own box (0 for a
// triangle mesh, whose triangles have none; infinite for a plane, a
// half-space nothing passes).
Real thickness(const ShapeDesc& shape) {
  if (shape.type == ShapeType::Mesh) return 0;
  if (shape.type == ShapeType::Plane) return kInf;
  const Aabb box = shapeAabb(shape, Transform{});
  return (box.hi - box.lo).minCoeff();
}

// The thinnest shape in the world, for watchFastBodies: a body that moved
// no further than its own thickness plus this cannot have passed anything.
Real thinnestShape(const WorldImpl& w) {
  Real thinnest = kInf;
  for (const ShapeRef& ref : w.shapes_)
    if (ref.alive) thinnest = std::min(thinnest, thickness(w.body(ref.body).shapes[static_cast<size_t>(ref.index)]));
  return thinnest;
}

void watchFastBodies(WorldImpl& w, StepContext& ctx) {
  // Cheap test first: a body that moved less than its radius of gyration
  // cannot have passed anything thinner than itself. Most steps no body
  // passes it, and it reads every moving body: on the pool's threads
  // (world/body_walk.hpp), the rest below in body order.
  const auto fast = [&](size_t i) {
    if (!ctx.moves(i)) return false;
    const Body& b = w.bodies_[i];
    if (!b.alive || !b.isDynamic() || b.asleep || b.ccd || b.shapes.empty()) return false;
    // A body whose filter meets no shape's in the world passes through
    // everything by design (a chain whose links collide with nothing).
    if (!w.broadphase_.mayPairWithAny(b.collision_group, b.collision_mask)) return false;
    return (b.position - ctx.step_start[i].x).norm() > Real(0.5) * std::sqrt(b.inertia_body.trace() / (2 * b.mass));
  };
  Real thinnest = -1;  // found once per step, and only when a body is fast enough to need it
  handleFound(w, fast, [&](size_t i) {
    const Body& b = w.bodies_[i];
    const Vec3 from = ctx.step_start[i].x, to = b.position;
    const Real travel = (to - from).norm();
    Real own = kInf;
    for (const ShapeDesc& s : b.shapes) own = std::min(own, thickness(s));
    if (!(travel > own)) return;
    if (thinnest < 0) thinnest = thinnestShape(w);
    if (!(travel > own + thinnest)) return;  // the query below would find nothing
    const Aabb path{from.cwiseMin(to), from.cwiseMax(to)};
    std::int32_t passed = -1;
    Real passed_thickness = 0;
    // Every candidate is visited and the lowest body index kept: the
    // tree's shape (which a restored snapshot rebuilds differently) must
    // not decide which body the report names.
    w.broadphase_.query(path, [&](int proxy) {
      const ShapeRef& ref = w.shapes_[static_cast<size_t>(w.broadphase_.user(proxy))];
      if (!ref.alive || ref.body.index == static_cast<std::int32_t>(i)) return true;
      // A shape the body never collides with (filter bits, a shared joint)
      // is one it may pass through.
      if (!w.shouldCollide(b, w.body(ref.body), w.bodyId(static_cast<int>(i)), ref.body)) return true;
      const Real t = thickness(w.body(ref.body).shapes[static_cast<size_t>(ref.index)]);
      if (!(travel > own + t)) return true;
      if (passed < 0 || ref.body.index < passed) {
        passed = ref.body.index;
        passed_thickness = t;
      }
      return true;
    });
    if (passed < 0) return;
    w.diagnose(static_cast<std::int32_t>(i), "fast body without CCD",
               "moved " + fmt(travel) + " m in one step across '" + w.body(passed).name + "' (" +
                   fmt(passed_thickness) + " m thick; the body " + fmt(own) +
                   " m): it can pass through without touching; set ccd on the body or use a smaller dt", true);
  });
}

void watchLimits(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  if (s.method == SolverMethod::LCP) {
    for (size_t isl = 0; isl < ctx.island_rows_estimate.size(); ++isl) {
      if (ctx.island_rows_estimate[isl] <= s.max_exact_rows) continue;
      std::int32_t first = -1;
      for (size_t i = 0; i < ctx.body_island.size() && first < 0; ++i)
        if (ctx.body_island[i] == static_cast<std::int32_t>(isl)) first = static_cast<std::int32_t>(i);
      if (first >= 0)
        w.diagnose(first, "exact solve too large",
                   "its island has about " + std::to_string(ctx.island_rows_estimate[isl]) +
                       " rows, over max_exact_rows = " + std::to_string(s.max_exact_rows) +
                       " (the exact LCP is dense: memory ~ rows^2, time ~ rows^3): solved by PGS instead", true);
    }
  }
  for (const int proxy : w.broadphase_.cappedProxies()) {
    const ShapeRef& ref = w.shapes_[static_cast<size_t>(w.broadphase_.user(proxy))];
    // A static shape's query is cut short under many bodies (a ground box),
    // but each of them found it with its own query: nothing was lost.
    if (!ref.alive || w.body(ref.body).type == BodyType::Static) continue;
    w.diagnose(ref.body.index, "contact pairs capped",
               "shape " + std::to_string(ref.index) + " overlapped more than max_pairs_per_shape = " +
                   std::to_string(s.max_pairs_per_shape) +
                   " other shapes; the rest were not tested (coincident or deeply overlapping bodies)", true);
  }
}

}  // namespace

void watchStep(WorldImpl& w, StepContext& ctx) {
  watchEnergy(w, ctx);
  watchJoints(w);
  w.stats_.max_penetration = watchPenetration(w, ctx);
  watchStacks(w, ctx);
  watchFastBodies(w, ctx);
  watchLimits(w, ctx);
  w.external_forces_ = false;
}

}  // namespace cairn::detail
