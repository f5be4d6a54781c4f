// Islands and sleeping.
//
// Awake dynamic bodies linked by touching contacts or joints form islands
// (union-find); static and kinematic bodies never link islands, so a floor
// under two separate stacks keeps them apart. Rows are built and solved
// island by island. An island whose bodies all stay below the sleep speeds
// for sleep_time sleeps: its bodies stop integrating, its contacts keep
// their cached state and make no rows, until something awake touches it or
// the API wakes it.
#include "world/world.hpp"

namespace cairn {

namespace {

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

void World::wakeIsland(std::int32_t island) {
  for (size_t i = 0; i < bodies_.size(); ++i) {
    if (bodies_[i].asleep && sleep_island_[i] == island) {
      bodies_[i].asleep = false;
      bodies_[i].sleep_timer = 0;
      sleep_island_[i] = -1;
    }
  }
}

void World::wakeBody(BodyId id) {
  Body& b = body(id);
  b.sleep_timer = 0;
  if (b.asleep) wakeIsland(sleep_island_[static_cast<size_t>(id.index)]);
}

void World::buildIslands() {
  const auto n = static_cast<std::int32_t>(bodies_.size());
  const auto movable = [&](BodyId id) { return !id.isWorld() && body(id).isDynamic(); };
  const auto moving = [&](BodyId id) {
    if (id.isWorld()) return false;
    const Body& b = body(id);
    if (b.type == BodyType::Kinematic) return b.linear_velocity.squaredNorm() + b.angular_velocity.squaredNorm() > 0;
    return b.isDynamic() && !b.asleep;
  };
  // Wake sleeping islands touched by something that moves.
  for (const Contact& c : contacts_) {
    if (!c.enabled) continue;
    const bool sa = !c.body_a.isWorld() && body(c.body_a).asleep, sb = !c.body_b.isWorld() && body(c.body_b).asleep;
    if (sa && moving(c.body_b)) wakeBody(c.body_a);
    if (sb && moving(c.body_a)) wakeBody(c.body_b);
  }
  for (const Joint& j : joints_) {
    if (j.broken) continue;
    if (!j.def.body_a.isWorld() && body(j.def.body_a).asleep && moving(j.def.body_b)) wakeBody(j.def.body_a);
    if (!j.def.body_b.isWorld() && body(j.def.body_b).asleep && moving(j.def.body_a)) wakeBody(j.def.body_b);
  }

  uf_parent_.resize(static_cast<size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) uf_parent_[static_cast<size_t>(i)] = i;
  for (const Contact& c : contacts_)
    if (c.enabled && movable(c.body_a) && movable(c.body_b)) unite(uf_parent_, c.body_a.index, c.body_b.index);
  for (const Joint& j : joints_)
    if (!j.broken && movable(j.def.body_a) && movable(j.def.body_b)) unite(uf_parent_, j.def.body_a.index, j.def.body_b.index);

  // Number the islands of awake dynamic bodies in body order.
  body_island_.assign(static_cast<size_t>(n), -1);
  std::vector<std::int32_t> roots(static_cast<size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) roots[static_cast<size_t>(i)] = findRoot(uf_parent_, i);
  std::vector<std::int32_t> island_of_root(static_cast<size_t>(n), -1);
  island_count_ = 0;
  for (std::int32_t i = 0; i < n; ++i) {
    const Body& b = bodies_[static_cast<size_t>(i)];
    if (!b.isDynamic() || b.asleep) continue;
    std::int32_t& isl = island_of_root[static_cast<size_t>(roots[static_cast<size_t>(i)])];
    if (isl < 0) isl = island_count_++;
    body_island_[static_cast<size_t>(i)] = isl;
  }
}

void World::updateSleep(Real h) {
  int sleeping = 0;
  if (!settings_.sleeping) {
    for (auto& b : bodies_) b.sleep_timer = 0;
  } else {
    // Each island sleeps as a whole, when its most restless body has been
    // slow for sleep_time.
    std::vector<Real> island_min(static_cast<size_t>(island_count_), kInf);
    const Real lin2 = settings_.sleep_linear_velocity * settings_.sleep_linear_velocity;
    const Real ang2 = settings_.sleep_angular_velocity * settings_.sleep_angular_velocity;
    for (size_t i = 0; i < bodies_.size(); ++i) {
      Body& b = bodies_[i];
      const std::int32_t isl = body_island_[i];
      if (isl < 0) continue;
      if (b.linear_velocity.squaredNorm() > lin2 || b.angular_velocity.squaredNorm() > ang2) b.sleep_timer = 0;
      else b.sleep_timer += h;
      island_min[static_cast<size_t>(isl)] = std::min(island_min[static_cast<size_t>(isl)], b.sleep_timer);
    }
    // An island touching a moving kinematic body stays awake.
    for (const Contact& c : contacts_) {
      for (const auto& [kin, dyn] : {std::pair{c.body_a, c.body_b}, std::pair{c.body_b, c.body_a}}) {
        if (kin.isWorld() || dyn.isWorld() || body(kin).type != BodyType::Kinematic) continue;
        const std::int32_t isl = body_island_[static_cast<size_t>(dyn.index)];
        if (isl >= 0 && body(kin).linear_velocity.squaredNorm() + body(kin).angular_velocity.squaredNorm() > 0)
          island_min[static_cast<size_t>(isl)] = 0;
      }
    }
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const std::int32_t isl = body_island_[i];
      if (isl < 0 || island_min[static_cast<size_t>(isl)] < settings_.sleep_time) continue;
      Body& b = bodies_[i];
      b.asleep = true;
      b.linear_velocity.setZero();
      b.angular_velocity.setZero();
    }
    // A sleeping island is remembered by its first body's index, so waking
    // any of its bodies wakes all of them.
    std::vector<std::int32_t> first(static_cast<size_t>(island_count_), -1);
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const std::int32_t isl = body_island_[i];
      if (isl >= 0 && bodies_[i].asleep && first[static_cast<size_t>(isl)] < 0) first[static_cast<size_t>(isl)] = static_cast<std::int32_t>(i);
    }
    for (size_t i = 0; i < bodies_.size(); ++i) {
      const std::int32_t isl = body_island_[i];
      if (isl >= 0 && bodies_[i].asleep) sleep_island_[i] = first[static_cast<size_t>(isl)];
    }
  }
  for (const auto& b : bodies_) sleeping += b.asleep ? 1 : 0;
  stats_.sleeping_bodies = sleeping;
}

}  // namespace cairn
