// Islands and sleeping.
//
// Awake dynamic bodies linked by contacts or joints form islands
// (union-find); static and kinematic bodies never link islands, so a floor
// under two separate stacks keeps them apart. Each island is solved on its
// own terms (its own stopping test and NNCG momentum in the PGS graph, or
// its own direct or exact solve). An island whose bodies all stay below the
// sleep speeds for sleep_time, and that is not being pushed out of a
// penetration, sleeps: its bodies stop integrating, its contacts keep their
// cached state and make no rows, until something awake touches it or the
// API wakes it.
#include "world/method_choice.hpp"
#include "world/step_stages.hpp"

#include <algorithm>

namespace cairn::detail {

namespace {

// A push-out is done when what is left of it is under 1% of the slop
// (5e-5 m at the default 5 mm).
constexpr Real kPushDone = Real(0.01);

std::int32_t findRoot(std::vector<std::int32_t>& parent, std::int32_t i) {
  while (parent[static_cast<size_t>(i)] != i) {
    parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    i = parent[static_cast<size_t>(i)];
  }
  return i;
}

void unite(std::vector<std::int32_t>& parent, std::int32_t a, std::int32_t b) {
  a = findRoot(parent, a);
  b = findRoot(parent, b);
  if (a == b) return;
  if (a < b) parent[static_cast<size_t>(b)] = a;  // the smaller index is the root: deterministic
  else parent[static_cast<size_t>(a)] = b;
}

}  // namespace

void WorldImpl::wakeIsland(std::int32_t island) {
  if (island < 0) return;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i].alive && bodies_[i].asleep && sleep_island_[i] == island) {
      bodies_[i].asleep = false;
      bodies_[i].sleep_timer = 0;
      sleep_island_[i] = -1;
    }
  }
}

void WorldImpl::wakeBody(BodyId id) {
  Body& b = body(id);
  b.sleep_timer = 0;
  if (b.asleep) wakeIsland(sleep_island_[static_cast<size_t>(id.index)]);
}

void buildIslands(WorldImpl& w, StepContext& ctx) {
  const auto n = static_cast<std::int32_t>(w.bodies_.size());
  // What the stage asks of each body, read once into a byte per slot: the
  // contact and joint loops below then look bodies up in this compact
  // array, not in the bodies themselves (a sleeping pile's islands stage
  // was mostly those lookups).
  enum : std::uint8_t { kAlive = 1, kDynamic = 2, kKinematic = 4, kAsleep = 8, kKinematicMoving = 16 };
  std::vector<std::uint8_t>& flags = ctx.body_flags;
  flags.assign(static_cast<size_t>(n), 0);
  bool anything_moves = false;  // moving(), below, of any slot
  for (size_t i = 0; i < flags.size(); ++i) {
    const Body& b = w.bodies_[i];
    std::uint8_t f = b.alive ? kAlive : 0;
    if (b.isDynamic()) f |= kDynamic;
    if (b.type == BodyType::Kinematic) f |= kKinematic;
    if (b.asleep) f |= kAsleep;
    if (b.isMovingKinematic()) f |= kKinematicMoving;
    flags[i] = f;
    anything_moves = anything_moves || (f & kKinematicMoving) || ((f & kDynamic) && !(f & kAsleep));
  }
  const auto has = [&](BodyId id, std::uint8_t bit) { return !id.isWorld() && (flags[static_cast<size_t>(id.index)] & bit); };
  const auto moving = [&](BodyId id) {
    return has(id, kKinematicMoving) || (has(id, kDynamic) && !has(id, kAsleep));
  };
  // Wake sleeping islands touched by something that moves: gather the
  // islands first, then wake them in one pass over the bodies.
  // When nothing moves (a world asleep), nothing wakes and no island is
  // numbered: the walks over the contacts and joints below are skipped
  // (they were most of an asleep pyramid's islands stage, a contact being
  // 700 bytes apart from the next).
  std::vector<std::int32_t>& to_wake = ctx.wake_list;
  to_wake.clear();
  const auto touch = [&](BodyId sleeper, BodyId other) {
    if (!has(sleeper, kAsleep) || !moving(other)) return;
    w.body(sleeper).sleep_timer = 0;
    to_wake.push_back(w.sleep_island_[static_cast<size_t>(sleeper.index)]);
  };
  // The same walk unites the dynamic bodies each contact and joint joins
  // (below, the sets of awake ones become the islands), sparing a second
  // walk over the 704-byte contacts (the 5,050-box pyramid's islands stage
  // about 0.35 ms a step on one thread, 0.32 to 0.35 with one walk). Waking
  // does not change which bodies are dynamic, and the unions come in the
  // same order, contacts then joints.
  ctx.uf_parent.resize(static_cast<size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) ctx.uf_parent[static_cast<size_t>(i)] = i;
  const auto join = [&](BodyId a, BodyId b) {
    if (has(a, kDynamic) && has(b, kDynamic)) unite(ctx.uf_parent, a.index, b.index);
  };
  if (anything_moves) {  // else no body below is awake: the sets are never read
    for (const Contact& c : w.contacts_) {
      if (!c.enabled) continue;
      touch(c.body_a, c.body_b);
      touch(c.body_b, c.body_a);
      join(c.body_a, c.body_b);
    }
    for (const Joint& j : w.joints_) {
      if (!j.alive || j.broken) continue;
      touch(j.def.body_a, j.def.body_b);
      touch(j.def.body_b, j.def.body_a);
      join(j.def.body_a, j.def.body_b);
    }
  }
  if (!to_wake.empty()) {
    std::sort(to_wake.begin(), to_wake.end());
    for (size_t i = 0; i < w.bodies_.size(); ++i) {
      if ((flags[i] & (kAlive | kAsleep)) != (kAlive | kAsleep) ||
          !std::binary_search(to_wake.begin(), to_wake.end(), w.sleep_island_[i]))
        continue;
      Body& b = w.bodies_[i];
      b.asleep = false;
      b.sleep_timer = 0;
      w.sleep_island_[i] = -1;
      flags[i] &= static_cast<std::uint8_t>(~kAsleep);
    }
  }

  // Number the islands of awake dynamic bodies in body order. The same
  // walk lists the kinematic bodies and counts the sleepers, so that no
  // later stage has to read every body for them.
  ctx.body_island.assign(static_cast<size_t>(n), -1);
  std::vector<std::int32_t>& island_of_root = ctx.island_root;
  island_of_root.assign(static_cast<size_t>(n), -1);
  ctx.island_count = 0;
  ctx.kinematic_bodies.clear();
  ctx.asleep_bodies = 0;
  for (std::int32_t i = 0; i < n; ++i) {
    const std::uint8_t f = flags[static_cast<size_t>(i)];
    if (!(f & kAlive)) continue;
    if (f & kAsleep) ++ctx.asleep_bodies;
    if (f & kKinematic) ctx.kinematic_bodies.push_back(i);
    if (!(f & kDynamic) || (f & kAsleep)) continue;
    std::int32_t& isl = island_of_root[static_cast<size_t>(findRoot(ctx.uf_parent, i))];
    if (isl < 0) isl = ctx.island_count++;
    ctx.body_island[static_cast<size_t>(i)] = isl;
  }
  ctx.island_method.assign(static_cast<size_t>(ctx.island_count), w.settings_.method);
  chooseIslandMethods(w, ctx);
  if (w.settings_.method == SolverMethod::LCP) limitExactIslands(w, ctx);
  countIslandMethods(w, ctx);
}

// The exact LCP is dense: its memory grows with the square of an island's
// rows and its time with the cube (pyramid-10 in one island took 30 s a
// step). An island whose rows, estimated before any is built, exceed
// max_exact_rows is solved by PGS this step; step_diagnostics.cpp reports it.
void limitExactIslands(WorldImpl& w, StepContext& ctx) {
  std::vector<std::int64_t>& rows = ctx.island_rows_estimate;
  rows.assign(static_cast<size_t>(ctx.island_count), 0);
  const auto island = [&](BodyId a, BodyId b) {
    for (const BodyId id : {a, b})
      if (!id.isWorld() && ctx.body_island[static_cast<size_t>(id.index)] >= 0)
        return ctx.body_island[static_cast<size_t>(id.index)];
    return -1;
  };
  for (const Contact& c : w.contacts_) {
    const std::int32_t isl = c.enabled ? island(c.body_a, c.body_b) : -1;
    if (isl >= 0)
      rows[static_cast<size_t>(isl)] += 3 * c.count + (c.rolling_friction > 0 || c.torsional_friction > 0 ? 3 : 0);
  }
  for (const Joint& j : w.joints_) {
    const std::int32_t isl = j.alive && !j.broken ? island(j.def.body_a, j.def.body_b) : -1;
    if (isl >= 0) rows[static_cast<size_t>(isl)] += 6;
  }
  for (size_t isl = 0; isl < rows.size(); ++isl)
    if (rows[isl] > w.settings_.max_exact_rows) ctx.island_method[isl] = SolverMethod::PGS;
}

void updateSleep(WorldImpl& w, StepContext& ctx) {
  const SolverSettings& s = w.settings_;
  int sleeping = 0;
  if (!s.sleeping) {
    for (Body& b : w.bodies_) b.sleep_timer = 0;
  } else {
    // Each island sleeps as a whole, when its most restless body has been
    // slow for sleep_time.
    std::vector<Real>& island_min = ctx.island_min;
    island_min.assign(static_cast<size_t>(ctx.island_count), kInf);
    const Real lin2 = s.sleep_linear_velocity * s.sleep_linear_velocity;
    const Real ang2 = s.sleep_angular_velocity * s.sleep_angular_velocity;
    for (size_t i = 0; i < w.bodies_.size(); ++i) {
      Body& b = w.bodies_[i];
      const std::int32_t isl = ctx.body_island[i];
      if (isl < 0) continue;
      if (!b.sleeping_allowed || b.linear_velocity.squaredNorm() > lin2 || b.angular_velocity.squaredNorm() > ang2)
        b.sleep_timer = 0;
      else
        b.sleep_timer += ctx.h;
      island_min[static_cast<size_t>(isl)] = std::min(island_min[static_cast<size_t>(isl)], b.sleep_timer);
    }
    // An island being pushed out of a penetration deeper than the slop
    // stays awake until the push-out is done: asleep it would keep the
    // penetration for good. Done means: no contact deeper than the slop by
    // more than kPushDone of it, and no body moved by its pseudo-velocity
    // (split impulse) by more than that in the last substep. The push-out
    // closes the excess geometrically (by 1 - contact_erp a step), so it
    // is never exactly zero: a tolerance lets a finished push-out sleep.
    const Real done = kPushDone * s.slop;
    // The walks below only keep awake an island about to sleep; with none
    // (an awake scene, or no island at all) they are skipped, a contact
    // being 700 bytes apart from the next.
    const bool about_to_sleep =
        std::any_of(island_min.begin(), island_min.end(), [&](Real m) { return m >= s.sleep_time; });
    if (about_to_sleep)
      for (const Contact& c : w.contacts_) {
        if (!c.enabled || c.count == 0) continue;
        const std::int32_t isl = std::max(c.body_a.isWorld() ? -1 : ctx.body_island[static_cast<size_t>(c.body_a.index)],
                                          c.body_b.isWorld() ? -1 : ctx.body_island[static_cast<size_t>(c.body_b.index)]);
        // Only an island about to sleep needs the look (an awake pyramid's
        // contacts cost this stage most of its time).
        if (isl < 0 || island_min[static_cast<size_t>(isl)] < s.sleep_time) continue;
        if (w.contactDepth(c) > s.slop + done) island_min[static_cast<size_t>(isl)] = 0;
      }
    for (std::int32_t si = 1; si <= ctx.dynamic_count && si < static_cast<std::int32_t>(ctx.pseudo.size()); ++si) {
      const SolverBody& p = ctx.pseudo[static_cast<size_t>(si)];
      if (ctx.hs * p.v.norm() <= done) continue;
      const std::int32_t isl = ctx.body_island[static_cast<size_t>(ctx.body_of_solver[static_cast<size_t>(si)])];
      if (isl >= 0) island_min[static_cast<size_t>(isl)] = 0;
    }
    // An island touching a moving kinematic body stays awake.
    if (about_to_sleep && !ctx.kinematic_bodies.empty())
      for (const Contact& c : w.contacts_) {
        for (const auto& [kin, dyn] : {std::pair{c.body_a, c.body_b}, std::pair{c.body_b, c.body_a}}) {
          if (kin.isWorld() || dyn.isWorld() || !w.body(kin).isMovingKinematic()) continue;
          const std::int32_t isl = ctx.body_island[static_cast<size_t>(dyn.index)];
          if (isl >= 0) island_min[static_cast<size_t>(isl)] = 0;
        }
      }
    // A sleeping island is remembered by its first body's index, so waking
    // any of its bodies wakes all of them.
    std::vector<std::int32_t>& first = ctx.sleep_first;
    first.assign(static_cast<size_t>(ctx.island_count), -1);
    for (size_t i = 0; i < w.bodies_.size(); ++i) {
      const std::int32_t isl = ctx.body_island[i];
      if (isl < 0 || island_min[static_cast<size_t>(isl)] < s.sleep_time) continue;
      Body& b = w.bodies_[i];  // awake: it has an island
      ++sleeping;
      b.asleep = true;
      b.linear_velocity.setZero();
      b.angular_velocity.setZero();
      if (first[static_cast<size_t>(isl)] < 0) first[static_cast<size_t>(isl)] = static_cast<std::int32_t>(i);
      w.sleep_island_[i] = first[static_cast<size_t>(isl)];
    }
  }
  // Those asleep since the islands stage (nothing wakes a body after it)
  // and those put to sleep just now.
  w.stats_.sleeping_bodies = ctx.asleep_bodies + sleeping;
}

void WorldImpl::putIslandToSleep(BodyId id) {
  // The body's island as the last step grouped it (or the body alone when
  // it was in none): every awake dynamic body of it stops now.
  const std::int32_t isl =
      static_cast<size_t>(id.index) < ctx_.body_island.size() ? ctx_.body_island[static_cast<size_t>(id.index)] : -1;
  const auto sleep = [&](size_t i, std::int32_t first) {
    Body& b = bodies_[i];
    b.asleep = true;
    b.linear_velocity.setZero();
    b.angular_velocity.setZero();
    b.sleep_timer = settings_.sleep_time;
    sleep_island_[i] = first;
  };
  if (!body(id).isDynamic()) return;
  if (isl < 0) {
    sleep(static_cast<size_t>(id.index), id.index);
    return;
  }
  std::int32_t first = -1;
  for (size_t i = 0; i < bodies_.size(); ++i) {
    if (!bodies_[i].alive || ctx_.body_island[i] != isl) continue;
    if (first < 0) first = static_cast<std::int32_t>(i);
    sleep(i, first);
  }
}

}  // namespace cairn::detail
