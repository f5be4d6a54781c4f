// The checks a snapshot's state passes before it may replace a World's
// (world/snapshot.hpp): every index in range, every handle naming a live
// object of its generation, free lists that list exactly the dead slots,
// counts that agree, values a step can carry. A file whose checksum holds
// passes them all; they are there for files made or changed by hand and for
// the fuzzer, so that no byte pattern reaches the step as a crash.
#include "world/snapshot.hpp"

#include "cairn/error.hpp"
#include "constraints/joint.hpp"

#include <algorithm>
#include <cmath>

namespace cairn::detail {

namespace {

class Checker {
 public:
  Checker(const WorldImpl& w, const std::string& object) : w_(w), object_(object) {}

  [[noreturn]] void fail(const std::string& field, const std::string& message) const {
    throw InputError(object_, field, "corrupted snapshot: " + message);
  }
  void require(bool ok, const std::string& field, const std::string& message) const {
    if (!ok) fail(field, message);
  }

  // A free list names each dead slot once and no live one.
  template <class Slots>
  void freeList(const Slots& slots, const std::vector<std::int32_t>& free, const std::string& field) const {
    std::vector<char> listed(slots.size(), 0);
    size_t dead = 0;
    for (const auto& s : slots) dead += s.alive ? 0 : 1;
    for (const std::int32_t i : free) {
      require(i >= 0 && static_cast<size_t>(i) < slots.size(), field, "a free slot index is out of range");
      require(!slots[static_cast<size_t>(i)].alive && !listed[static_cast<size_t>(i)], field,
              "the free list names a live slot or one slot twice");
      listed[static_cast<size_t>(i)] = 1;
    }
    require(free.size() == dead, field, "the free list does not list every dead slot");
  }

  bool liveBody(BodyId id) const { return w_.valid(id); }
  bool bodyOrWorld(BodyId id) const { return id.index == -1 ? id.generation == 0 : liveBody(id); }

  void bodies() const {
    const auto& bodies = w_.bodies_;
    freeList(bodies, w_.free_bodies_, "bodies");
    int alive = 0;
    for (size_t i = 0; i < bodies.size(); ++i) {
      const Body& b = bodies[i];
      if (!b.alive) continue;
      ++alive;
      const std::string f = "bodies[" + std::to_string(i) + "]";
      require(b.position.allFinite() && b.orientation.coeffs().allFinite() && b.linear_velocity.allFinite() &&
                  b.angular_velocity.allFinite(),
              f, "the state is not finite");
      require(std::abs(b.orientation.norm() - 1) < Real(1e-6), f, "the orientation is not a unit quaternion");
      require(b.shape_ids.size() == b.shapes.size(), f, "shapes and shape slots differ in number");
      require(b.next_impulse <= b.impulses.size(), f, "the next timed impulse is past the last");
      for (size_t k = 0; k < b.shapes.size(); ++k) {
        validateShape(f, "shapes[" + std::to_string(k) + "]", b.shapes[k], b.type);
        const std::int32_t slot = b.shape_ids[k];
        require(slot >= 0 && static_cast<size_t>(slot) < w_.shapes_.size(), f, "a shape slot is out of range");
        const ShapeRef& ref = w_.shapes_[static_cast<size_t>(slot)];
        require(ref.alive && ref.body.index == static_cast<std::int32_t>(i) && ref.body.generation == b.generation &&
                    ref.index == static_cast<std::int32_t>(k),
                f, "a shape slot does not point back to its body");
      }
    }
    require(alive == w_.alive_bodies_, "bodies", "the live body count does not match");
    require(w_.sleep_island_.size() == bodies.size() && w_.ctx_.body_island.size() == bodies.size() &&
                w_.ctx_.step_start.size() == bodies.size(),
            "sleep", "per-body arrays differ in length from the bodies");
  }

  void shapes() const {
    freeList(w_.shapes_, w_.free_shapes_, "shapes");
    for (size_t i = 0; i < w_.shapes_.size(); ++i) {
      const ShapeRef& r = w_.shapes_[i];
      if (!r.alive) continue;
      const std::string f = "shapes[" + std::to_string(i) + "]";
      require(liveBody(r.body), f, "the shape's body is not a live body");
      const Body& b = w_.body(r.body);
      require(r.index >= 0 && static_cast<size_t>(r.index) < b.shape_ids.size() &&
                  b.shape_ids[static_cast<size_t>(r.index)] == static_cast<std::int32_t>(i),
              f, "the body does not list the shape");
    }
  }

  void joints() const {
    freeList(w_.joints_, w_.free_joints_, "joints");
    for (size_t i = 0; i < w_.joints_.size(); ++i) {
      const Joint& j = w_.joints_[i];
      if (!j.alive) continue;
      const std::string f = "joints[" + std::to_string(i) + "]";
      require(bodyOrWorld(j.def.body_a) && bodyOrWorld(j.def.body_b), f, "the joint's bodies are not live bodies");
      require(j.warm.size() == static_cast<size_t>(kMaxJointRows), f, "the warm-start impulses have the wrong count");
      require(j.local_motor_axes.size() == j.def.motor_axes.size() &&
                  j.def.motor_targets.size() >= j.def.motor_axes.size() &&
                  j.def.motor_max_torques.size() >= j.def.motor_axes.size(),
              f, "the motor axes, targets and torques differ in number");
      validateJointDef(j.def, w_.bodySlots());
    }
  }

  void springs() const {
    freeList(w_.springs_, w_.free_springs_, "springs");
    for (size_t i = 0; i < w_.springs_.size(); ++i) {
      const Spring& s = w_.springs_[i];
      if (s.alive)
        require(bodyOrWorld(s.def.body_a) && bodyOrWorld(s.def.body_b), "springs[" + std::to_string(i) + "]",
                "the spring's bodies are not live bodies");
    }
  }

  void contacts() const {
    const auto& shapes = w_.shapes_;
    const auto shapeOf = [&](std::int32_t s, BodyId b) {
      return s >= 0 && static_cast<size_t>(s) < shapes.size() && shapes[static_cast<size_t>(s)].alive &&
             shapes[static_cast<size_t>(s)].body == b;
    };
    for (size_t i = 0; i < w_.contacts_.size(); ++i) {
      const Contact& c = w_.contacts_[i];
      const std::string f = "contacts[" + std::to_string(i) + "]";
      require(c.shape_a < c.shape_b && shapeOf(c.shape_a, c.body_a) && shapeOf(c.shape_b, c.body_b), f,
              "the contact's shapes or bodies are not live, or out of order");
      require(c.triangle >= -1, f, "the triangle index is below -1");
      require(i == 0 || w_.contacts_[i - 1].key() < c.key(), f, "the contact cache is not sorted by key");
    }
    for (size_t i = 1; i < w_.pair_materials_.size(); ++i)
      require(w_.pair_materials_[i - 1].key < w_.pair_materials_[i].key, "contacts",
              "the pair materials are not sorted by key");
  }

  void clock() const {
    validateSettings(w_.settings_);
    require(w_.gravity_.allFinite(), "gravity", "not finite");
    require(w_.step_count_ >= 0 && std::isfinite(w_.time_) && w_.time_ >= 0, "clock", "the step count or time is negative");
    require(std::isfinite(w_.ctx_.h) && w_.ctx_.h >= 0, "clock", "the last step size is not finite");
  }

 private:
  const WorldImpl& w_;
  const std::string& object_;
};

}  // namespace

void checkBroadPhaseState(const WorldImpl& w, const std::vector<BroadPhase::ProxyState>& proxies, int free_head,
                          const std::string& object) {
  const Checker c(w, object);
  const auto n = static_cast<int>(proxies.size());
  // The shapes read so far name their proxies; each live proxy must be its shape's.
  std::vector<char> seen(proxies.size(), 0);
  for (int h = 0; h < n; ++h) {
    const BroadPhase::ProxyState& p = proxies[static_cast<size_t>(h)];
    if (!p.alive) continue;
    c.require(p.user >= 0 && static_cast<size_t>(p.user) < w.shapes_.size() && w.shapes_[static_cast<size_t>(p.user)].alive &&
                  w.shapes_[static_cast<size_t>(p.user)].proxy == h,
              "broadphase", "a proxy does not belong to a live shape");
    c.require(p.owner == w.shapes_[static_cast<size_t>(p.user)].body.index, "broadphase",
              "a proxy's owner is not its shape's body");
    const bool infinite = p.fat.isInfinite();
    c.require(!std::isnan(p.fat.lo.sum()) && !std::isnan(p.fat.hi.sum()) && (infinite || (p.fat.lo.array() <= p.fat.hi.array()).all()),
              "broadphase", "a proxy's box is not a box");
  }
  for (const ShapeRef& r : w.shapes_)
    if (r.alive)
      c.require(r.proxy >= 0 && r.proxy < n && proxies[static_cast<size_t>(r.proxy)].alive, "broadphase",
                "a live shape has no live proxy");
  // The free list: a chain through the dead proxies, each once.
  int dead = 0;
  for (const auto& p : proxies) dead += p.alive ? 0 : 1;
  int steps = 0;
  for (int h = free_head; h >= 0; h = proxies[static_cast<size_t>(h)].next_free) {
    c.require(h < n && !proxies[static_cast<size_t>(h)].alive && !seen[static_cast<size_t>(h)], "broadphase",
              "the free proxy list is broken");
    seen[static_cast<size_t>(h)] = 1;
    ++steps;
  }
  c.require(free_head >= -1 && steps == dead, "broadphase", "the free proxy list does not list every dead proxy");
}

void checkSnapshotState(const WorldImpl& w, const std::string& object) {
  const Checker c(w, object);
  c.clock();
  c.bodies();
  c.shapes();
  c.joints();
  c.springs();
  c.contacts();
}

}  // namespace cairn::detail
