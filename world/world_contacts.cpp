// Stage 2 of the step: broadphase -> filtering -> narrowphase -> contact
// cache (warm-start impulses matched by feature id) -> callback; and, after
// the solve, the contact events.
#include "cairn/error.hpp"
#include "collision/aabb.hpp"
#include "collision/narrowphase.hpp"
#include "world/grow_capacity.hpp"
#include "world/parallel_thresholds.hpp"
#include "world/sorted_keys.hpp"
#include "world/step_stages.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace cairn::detail {

namespace {

std::uint64_t bodyPairKey(BodyId a, BodyId b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a.index, b.index));
  const auto hi = static_cast<std::uint32_t>(std::max(a.index, b.index));
  return (std::uint64_t(lo) << 32) | hi;
}

// The pair's friction and restitution: the bodies' combined (geometric
// mean of the frictions, the larger restitution, Bullet's and Box2D's
// rules), or the pair's own material if one was set.
void combineMaterials(const WorldImpl& w, const Body& ba, const Body& bb, Contact& c) {
  c.friction = std::sqrt(ba.friction * bb.friction);
  c.restitution = std::max(ba.restitution, bb.restitution);
  c.rolling_friction = std::max(ba.rolling_friction, bb.rolling_friction);
  c.torsional_friction = std::max(ba.torsional_friction, bb.torsional_friction);
  const std::uint64_t pk = bodyPairKey(c.body_a, c.body_b);
  const auto mat = std::lower_bound(w.pair_materials_.begin(), w.pair_materials_.end(), pk,
                                    [](const WorldImpl::PairMaterial& x, std::uint64_t k) { return x.key < k; });
  if (mat != w.pair_materials_.end() && mat->key == pk) {
    c.friction = mat->friction;
    c.restitution = mat->restitution;
  }
}

// B's pose in A's frame: the offset R_a^T (x_b - x_a) and the rotation
// q_a^-1 q_b (what recycling compares with where a manifold was made).
struct RelativePose {
  Vec3 offset;
  Quat rotation;
};
RelativePose relativePose(const Body& a, const Body& b) {
  const Quat a_inv = a.orientation.conjugate();
  return {rotate(a_inv, b.position - a.position), a_inv * b.orientation};
}

// Contact recycling, after Jolt's body pair cache (PhysicsSettings::
// mBodyPairCacheMaxDeltaPositionSq and mBodyPairCacheCosMaxDeltaRotationDiv2).
// A manifold's points are fixed on the two bodies, so while B has moved less
// than recycle_distance and turned less than recycle_angle relative to A
// since the narrowphase made the manifold, those points still describe the
// contact: the manifold is kept and what depends on the present poses
// (normal, depths, approach speeds) recomputed. The bounds are measured from
// where the manifold was made, not from the last step, so slow drift cannot
// add up past them. Only a pair that made exactly one convex manifold (no
// mesh triangles) is recycled. Returns whether `out` got the recycled contact.
bool recycleManifold(const WorldImpl& w, const Body& ba, const Body& bb, std::int32_t sa, std::int32_t sb,
                     const std::vector<Contact>::const_iterator first, const std::vector<Contact>& old,
                     Real cos_half_angle, std::vector<Contact>& out) {
  const SolverSettings& s = w.settings_;
  if (!(s.recycle_distance > 0) || !(s.recycle_angle > 0)) return false;
  if (first == old.end() || first->shape_a != sa || first->shape_b != sb) return false;
  const Contact& o = *first;
  const auto next = first + 1;
  if (o.triangle != -1 || o.count == 0 || !o.touching || (next != old.end() && next->shape_a == sa && next->shape_b == sb))
    return false;
  const RelativePose now = relativePose(ba, bb);
  // Written to fail on a NaN reference pose (a body whose shapes changed).
  if (!((now.offset - o.made_offset).squaredNorm() <= s.recycle_distance * s.recycle_distance)) return false;
  // The angle between two rotations: |q1 . q2| = cos(angle / 2).
  if (!(std::abs(now.rotation.coeffs().dot(o.made_rotation.coeffs())) >= cos_half_angle)) return false;
  out.push_back(o);  // made in place: one copy of the 700-byte manifold, not two
  Contact& c = out.back();
  c.enabled = true;  // the callback decides again
  c.normal = rotate(ba.orientation, o.made_normal);
  combineMaterials(w, ba, bb, c);
  const Transform ta = ba.transform(), tb = bb.transform();
  for (int i = 0; i < c.count; ++i) {
    ContactPointState& p = c.points[i];
    const Vec3 on_a = ta.apply(p.local_a), on_b = tb.apply(p.local_b);
    p.depth = (on_a - on_b).dot(c.normal);
    p.approach_speed = c.normal.dot(bb.velocityAt(on_b) - ba.velocityAt(on_a));
  }
  return true;
}

}  // namespace

void WorldImpl::setPairMaterial(BodyId a, BodyId b, Real friction, Real restitution) {
  if (!std::isfinite(friction) || friction < 0) throw InputError("pair material", "friction", "must be finite and >= 0");
  if (!std::isfinite(restitution) || restitution < 0 || restitution > 1)
    throw InputError("pair material", "restitution", "must lie in [0, 1]");
  const std::uint64_t key = bodyPairKey(a, b);
  auto it = std::lower_bound(pair_materials_.begin(), pair_materials_.end(), key,
                             [](const PairMaterial& m, std::uint64_t k) { return m.key < k; });
  if (it != pair_materials_.end() && it->key == key) *it = {key, friction, restitution};
  else pair_materials_.insert(it, {key, friction, restitution});
}

namespace {
// Two body slots (the world is -1) as one key, whichever comes first.
std::uint64_t bodyPairKey(std::int32_t a, std::int32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
}
}  // namespace

bool WorldImpl::shouldCollide(const Body& a, const Body& b, BodyId ia, BodyId ib) const {
  if (ia.index == ib.index) return false;
  if (!a.isDynamic() && !b.isDynamic()) return false;  // static and kinematic never collide with each other
  if ((a.collision_group & b.collision_mask) == 0 || (b.collision_group & a.collision_mask) == 0) return false;
  // A pair that shares a joint does not collide unless the joint says so
  // (the sorted list collide() makes each step: a search, not a walk over
  // every joint for every pair).
  if (std::binary_search(ctx_.jointed_pairs.begin(), ctx_.jointed_pairs.end(), bodyPairKey(ia.index, ib.index)))
    return false;
  if (filter_callback_ && !filter_callback_(ia, ib)) return false;
  return true;
}

Real WorldImpl::contactDepth(const Contact& c) const {
  // Per point -n . (p_b - p_a), p = x + R l: with the normal taken into
  // each body's frame once, -(n . (x_b - x_a) + (R_b^T n) . l_b - (R_a^T n) . l_a),
  // two rotations a manifold instead of two a point. The world body sits at
  // the origin, unrotated.
  const auto side = [&](BodyId id, Vec3& x, Vec3& n_local) {
    if (id.isWorld()) {
      x.setZero();
      n_local = c.normal;
      return;
    }
    const Body& b = bodies_[static_cast<size_t>(id.index)];
    x = b.position;
    n_local = rotate(b.orientation.conjugate(), c.normal);
  };
  Vec3 xa, xb, na, nb;
  side(c.body_a, xa, na);
  side(c.body_b, xb, nb);
  const Real centres = c.normal.dot(xb - xa);
  Real depth = 0;
  for (int i = 0; i < c.count; ++i)
    depth = std::max(depth, -(centres + nb.dot(c.points[i].local_b) - na.dot(c.points[i].local_a)));
  return depth;
}

namespace {

// A pair of bodies of which nothing moves this step: each asleep, static or
// kinematic without a velocity, one asleep. Its contacts stay as they were.
// (A moving kinematic body must be collided: its contact is what wakes the
// sleeper it reaches.)
bool pairAtRest(const Body& a, const Body& b) {
  const auto still = [](const Body& x) { return x.asleep || (!x.isDynamic() && !x.isMovingKinematic()); };
  return still(a) && still(b) && (a.asleep || b.asleep);
}

// Whether every candidate pair is at rest and may still collide.
bool pairsAtRest(const WorldImpl& w) {
  for (const auto& [pa, pb] : w.pairs_) {
    const ShapeRef& ra = w.shapes_[static_cast<size_t>(w.broadphase_.user(pa))];
    const ShapeRef& rb = w.shapes_[static_cast<size_t>(w.broadphase_.user(pb))];
    const Body& ba = w.body(ra.body);
    const Body& bb = w.body(rb.body);
    if (!pairAtRest(ba, bb) || !w.shouldCollide(ba, bb, ra.body, rb.body)) return false;
  }
  return true;
}

// The first of last step's contacts whose key is not below `key` (they
// are sorted by key), searched in their keys alone, not the 704-byte
// contacts, from `cursor`: the last pair's answer (world/sorted_keys.hpp).
std::vector<Contact>::const_iterator firstOldContact(const std::vector<Contact>& old,
                                                     const std::vector<std::uint64_t>& old_keys, std::uint64_t key,
                                                     size_t& cursor) {
  return old.begin() + static_cast<std::ptrdiff_t>(lowerBoundFrom(old_keys, key, cursor));
}

// A pair through the narrowphase: its manifolds as new contacts, each
// point's anchors fixed on the two bodies. Kept out of collidePair, whose
// common paths (a pair at rest, a recycled manifold) stay small: with this
// inside it, GCC's inlining in collidePair changed with unrelated edits to
// this file, and collide on one thread with it (11.1 against 11.4 ms a step
// on the 5,050-box pyramid: docs/performance.md, "Earlier: what the calling
// thread did alone").
[[gnu::noinline]] void narrowphasePair(const WorldImpl& w, const Body& ba, const Body& bb, const ShapeRef& ra,
                                       const ShapeRef& rb, std::int32_t sa, std::int32_t sb, Real h,
                                       std::vector<Manifold>& manifolds, std::vector<Contact>& out) {
  const ShapeDesc& sda = ba.shapes[static_cast<size_t>(ra.index)];
  const ShapeDesc& sdb = bb.shapes[static_cast<size_t>(rb.index)];
  const Real margin = std::max(contactReach(ba, w.settings_.contact_margin, h), contactReach(bb, w.settings_.contact_margin, h));
  manifolds.clear();
  cairn::collide(sda, ba.transform() * sda.local, sdb, bb.transform() * sdb.local, margin, manifolds);
  for (const Manifold& m : manifolds) {
    if (m.count == 0) continue;
    Contact& c = out.emplace_back();  // made in place, not copied in: 704 bytes
    c.shape_a = sa;
    c.shape_b = sb;
    c.triangle = m.triangle;
    c.body_a = ra.body;
    c.body_b = rb.body;
    c.normal = m.normal;
    c.count = m.count;
    combineMaterials(w, ba, bb, c);
    const RelativePose made = relativePose(ba, bb);
    c.made_offset = made.offset;
    c.made_rotation = made.rotation;
    c.made_normal = rotate(ba.orientation.conjugate(), m.normal);
    const Transform ta = ba.transform(), tb = bb.transform();
    for (int i = 0; i < m.count; ++i) {
      ContactPointState& p = c.points[i];
      const ContactPoint& q = m.points[i];
      p.feature_id = q.feature_id;
      p.depth = q.depth;
      // Surface points: A's at position + n d/2, B's at position - n d/2.
      const Vec3 on_a = q.position + m.normal * (q.depth / 2), on_b = q.position - m.normal * (q.depth / 2);
      p.local_a = ta.applyInverse(on_a);
      p.local_b = tb.applyInverse(on_b);
      p.approach_speed = m.normal.dot(bb.velocityAt(on_b) - ba.velocityAt(on_a));
    }
    c.touching = true;
  }
}

// Warm start of a contact the narrowphase made: last step's contact of the
// same key gives its impulses, point by point by feature id or, failing
// that, within 2 cm on body A. `from` is the first of last step's contacts
// not below the pair's first key, which no key of the pair is below: the
// match is a few entries on (many, for a mesh pair's triangles), found by
// the gallop from there (world/sorted_keys.hpp), not a search over the
// whole list. Returns whether there was one.
bool warmStartMade(const std::vector<Contact>& old, const std::vector<std::uint64_t>& old_keys, size_t from,
                   Contact& c) {
  const std::uint64_t key = c.key();
  const size_t i = lowerBoundFrom(old_keys, key, from);
  if (i == old_keys.size() || old_keys[i] != key) {
    c.began = true;
    return false;
  }
  const Contact& o = old[i];
  c.began = !o.touching;
  c.rolling_impulse = o.rolling_impulse;
  for (int p = 0; p < c.count; ++p) {
    ContactPointState& q = c.points[p];
    const ContactPointState* match = nullptr;
    for (int k = 0; k < o.count && !match; ++k)
      if (o.points[k].feature_id == q.feature_id) match = &o.points[k];
    for (int k = 0; k < o.count && !match; ++k)
      if ((o.points[k].local_a - q.local_a).squaredNorm() < Real(4e-4)) match = &o.points[k];
    if (match) {
      q.normal_impulse = match->normal_impulse;
      q.friction_impulse = match->friction_impulse;
    }
  }
  return true;
}

// One candidate pair (broadphase handles pa, pb): its contacts appended to
// `out`, last step's kept as they were when neither body moves, else a
// recycled manifold, else the narrowphase's, warm started from last
// step's. Reads the world only (the pool's threads run it side by side);
// `manifolds` is scratch; `counts` grows by what the contacts were;
// `cursor` follows last step's keys from pair to pair (firstOldContact).
void collidePair(const WorldImpl& w, const std::vector<std::uint64_t>& old_keys, size_t& cursor, int pa, int pb, Real h,
                 Real cos_half_angle, std::vector<Manifold>& manifolds, std::vector<Contact>& out,
                 StepContext::PairCounts& counts) {
  const std::vector<Contact>& old = w.old_contacts_;
  std::int32_t sa = w.broadphase_.user(pa), sb = w.broadphase_.user(pb);
  if (sa > sb) std::swap(sa, sb);
  const ShapeRef& ra = w.shapes_[static_cast<size_t>(sa)];
  const ShapeRef& rb = w.shapes_[static_cast<size_t>(sb)];
  const Body& ba = w.body(ra.body);
  const Body& bb = w.body(rb.body);
  if (!w.shouldCollide(ba, bb, ra.body, rb.body)) return;
  // Last step's contacts of this pair: their keys' high bits are the two
  // shapes.
  const auto cached = firstOldContact(old, old_keys, Contact::keyOf(sa, sb, -1), cursor);
  if (pairAtRest(ba, bb)) {  // keep the cached contacts as they were, impulses and all
    for (auto it = cached; it != old.end() && it->shape_a == sa && it->shape_b == sb; ++it) {
      out.push_back(*it);
      out.back().began = !it->touching;
      counts.began += out.back().began;
      ++counts.continued;
    }
    return;
  }
  if (recycleManifold(w, ba, bb, sa, sb, cached, old, cos_half_angle, out)) {
    out.back().began = false;  // recycled only from a touching manifold
    ++counts.recycled;
    ++counts.continued;
    return;
  }
  const size_t first = out.size();
  narrowphasePair(w, ba, bb, ra, rb, sa, sb, h, manifolds, out);
  for (size_t i = first; i < out.size(); ++i) {
    counts.continued += warmStartMade(old, old_keys, static_cast<size_t>(cached - old.begin()), out[i]);
    counts.began += out[i].began;
  }
}

}  // namespace

void collide(WorldImpl& w, StepContext& ctx) {
  const Real h = ctx.h;
  const SolverSettings& settings_ = w.settings_;
  BroadPhase& broadphase_ = w.broadphase_;
  std::vector<Contact>& contacts_ = w.contacts_;
  std::vector<Contact>& old_contacts_ = w.old_contacts_;
  std::vector<std::uint64_t>& old_keys = ctx.old_keys;
  const auto body = [&](BodyId id) -> const Body& { return w.body(id); };
  // 1. Broadphase: move the proxies of bodies that can move.
  w.moveProxies(kWorldBody, h);
  broadphase_.setMaxPairsPerProxy(settings_.max_pairs_per_shape);
  // The moved proxies' tree queries only read the tree: split among the
  // pool's threads when there are enough of them (the same pairs in the
  // same order whatever the split).
  const int query_parts = w.pool_ ? w.pool_->threads() : 1;
  const bool pairs_changed = broadphase_.updatePairs(w.pairs_, query_parts, [&](int moved, auto&& query) {
    if (w.pool_ && moved >= kParallelMovedProxies)
      w.pool_->parallelFor(moved, [&](int begin, int end) { query(WorkerPool::currentThread(), begin, end); });
    else
      query(0, 0, moved);
  });
  std::vector<std::uint64_t>& jointed = ctx.jointed_pairs;  // for shouldCollide
  jointed.clear();
  for (const Joint& j : w.joints_)
    if (j.alive && !j.broken && !j.def.collide_connected)
      jointed.push_back(bodyPairKey(j.def.body_a.index, j.def.body_b.index));
  std::sort(jointed.begin(), jointed.end());

  // A world at rest: the same pairs as last step, every one between bodies
  // that cannot move. The pass below would copy each contact as it was
  // (a fully asleep pile-1000's collide was mostly that copy); instead the
  // contacts stay where they are, and last step's list is emptied so that
  // the events see nothing end.
  const bool at_rest = !pairs_changed && pairsAtRest(w);
  ctx.some_began = true;  // unknown until found below
  ctx.all_continued = false;
  if (at_rest) {
    old_contacts_.clear();
    old_keys.clear();
    bool began = false;
    for (Contact& c : contacts_) {  // impulses and all, as a pair at rest below
      c.began = !c.touching;
      began = began || c.began;
    }
    ctx.some_began = began;
    ctx.all_continued = true;  // last step's list is empty
  } else {
    // 2. Narrowphase over the candidate pairs, matching last step's contacts
    //    (warm start: each made contact takes the impulses of last step's
    //    with the same key and feature ids).
    std::swap(old_contacts_, contacts_);
    contacts_.clear();
    // Room for as many contacts as last step made, so that the list does not
    // double its way up (each doubling a copy into fresh memory, every page
    // of it a fault: the second step of the 5,050-box pyramid, whose list
    // is the one the first step left empty, faulted 5,100 times, 2,600
    // with it). Not at the first step: there the growing list's freed
    // blocks serve the islands', the row build's, the solve's and the
    // events' lists (docs/performance.md).
    reserveGrowing(contacts_, old_contacts_.size());
    const auto by_key = [](const Contact& x, const Contact& y) { return x.key() < y.key(); };
    // Last step's keys, read once and checked for order in their own
    // array (a walk over the contacts would read a 704-byte contact each).
    const auto readKeys = [&] {
      old_keys.resize(old_contacts_.size());
      for (size_t i = 0; i < old_contacts_.size(); ++i) old_keys[i] = old_contacts_[i].key();
    };
    readKeys();
    if (!std::is_sorted(old_keys.begin(), old_keys.end())) {
      std::sort(old_contacts_.begin(), old_contacts_.end(), by_key);
      readKeys();
    }
    const Real cos_half_angle = std::cos(settings_.recycle_angle / 2);
    // A range of pairs: appends their contacts to `out`, counts what they
    // were, and says whether they came in strictly increasing key order
    // (each key read as it is written, not in a walk over the list after;
    // strictly, so that in order the keys are also unique and the counts
    // say which of last step's contacts continue).
    const auto pairRange = [&](int begin, int end, std::vector<Contact>& out, std::vector<Manifold>& manifolds,
                               StepContext::PairCounts& counts) {
      bool sorted = true;
      size_t cursor = 0;  // in last step's keys (firstOldContact)
      for (int k = begin; k < end; ++k) {
        const auto& [pa, pb] = w.pairs_[static_cast<size_t>(k)];
        const size_t first = out.size();
        collidePair(w, old_keys, cursor, pa, pb, h, cos_half_angle, manifolds, out, counts);
        for (size_t i = std::max<size_t>(first, 1); i < out.size(); ++i) sorted = sorted && out[i - 1].key() < out[i].key();
      }
      return sorted;
    };
    const int pair_count = static_cast<int>(w.pairs_.size());
    if (ctx.pair_manifolds.empty()) ctx.pair_manifolds.resize(1);  // the calling thread's scratch
    // The pairs are independent: split among the pool's threads in ranges
    // sized by last step's time (world/cost_split.hpp), each appending to
    // its own list, the lists joined in pair order (the same contacts in
    // the same order whatever the split). The user's filter callback is
    // called from the stepping thread only.
    bool in_order = true;
    StepContext::PairCounts total;
    if (w.pool_ && pair_count >= kParallelPairs && !w.filter_callback_) {
      const auto threads = static_cast<size_t>(w.pool_->threads());
      ctx.pair_contacts.resize(threads);
      ctx.pair_manifolds.resize(threads);
      ctx.pair_counts.assign(threads, {});
      ctx.pair_sorted.assign(threads, 1);
      for (size_t t = 1; t < threads; ++t) ctx.pair_contacts[t].clear();  // a thread may have no pairs
      ctx.pair_split.plan(pair_count, static_cast<int>(threads));
      w.pool_->parallelFor(static_cast<int>(threads), [&](int first, int last) {  // one range per thread
        for (int r = first; r < last; ++r) {
          const auto t = static_cast<size_t>(r);
          const auto start = std::chrono::steady_clock::now();
          std::vector<Contact>& out = t == 0 ? contacts_ : ctx.pair_contacts[t];
          ctx.pair_sorted[t] =
              pairRange(ctx.pair_split.begin(r), ctx.pair_split.end(r), out, ctx.pair_manifolds[t], ctx.pair_counts[t]);
          ctx.pair_split.record(r, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        }
      });
      for (size_t t = 0; t < threads; ++t) {
        if (t > 0) {
          const std::vector<Contact>& part = ctx.pair_contacts[t];
          if (!part.empty() && !contacts_.empty() && !(contacts_.back().key() < part.front().key())) in_order = false;
          contacts_.insert(contacts_.end(), part.begin(), part.end());
        }
        in_order = in_order && ctx.pair_sorted[t];
        total.recycled += ctx.pair_counts[t].recycled;
        total.began += ctx.pair_counts[t].began;
        total.continued += ctx.pair_counts[t].continued;
      }
    } else {
      in_order = pairRange(0, pair_count, contacts_, ctx.pair_manifolds[0], total);
    }
    w.stats_.recycled_contacts += total.recycled;
    ctx.some_began = total.began > 0;
    ctx.all_continued = in_order && static_cast<size_t>(total.continued) == old_contacts_.size();
    // Contacts in key order (deterministic, and for the lookup below). The
    // broadphase hands pairs over in a stable order, so this is usually
    // sorted already: checked as they were written, which spares moving
    // every contact.
    if (!in_order) std::stable_sort(contacts_.begin(), contacts_.end(), by_key);
  }

  // 3. Warm start: done for each pair as its contacts were made
  //    (collidePair); a world at rest keeps its contacts as they were.

  // 4. The user's callback may veto or modify each contact.
  if (w.contact_callback_) {
    for (Contact& c : contacts_) {
      ContactInfo info;
      info.body_a = c.body_a;
      info.body_b = c.body_b;
      info.shape_a = c.shape_a;
      info.shape_b = c.shape_b;
      info.normal = c.normal;
      info.count = c.count;
      const Transform ta = body(c.body_a).transform();
      int deepest = 0;
      for (int i = 0; i < c.count; ++i) {
        info.points[i] = ta.apply(c.points[i].local_a);
        info.depths[i] = c.points[i].depth;
        if (c.points[i].depth > c.points[deepest].depth) deepest = i;
      }
      info.relative_velocity = body(c.body_b).velocityAt(info.points[deepest]) - body(c.body_a).velocityAt(info.points[deepest]);
      info.friction = c.friction;
      info.restitution = c.restitution;
      w.contact_callback_(info);
      c.enabled = info.enabled;
      c.friction = std::max(Real(0), info.friction);
      c.restitution = std::clamp(info.restitution, Real(0), Real(1));
    }
  }
}

// Begin events are emitted after the solve so they carry the impulse of
// their first step; End events name contacts that no longer touch (and
// those removed with a body or shape since the last step).
void emitContactEvents(WorldImpl& w, StepContext& ctx) {
  const std::vector<Contact>& contacts_ = w.contacts_;
  const std::vector<Contact>& old = w.old_contacts_;
  const auto body = [&](BodyId id) -> const Body& { return w.body(id); };
  const auto event = [&](const Contact& c, ContactEvent::Type type) {
    ContactEvent e;
    e.type = type;
    e.step = w.step_count_;
    e.body_a = c.body_a;
    e.body_b = c.body_b;
    e.shape_a = c.shape_a;
    e.shape_b = c.shape_b;
    e.normal = c.normal;
    return e;
  };
  // Begin events of contacts [begin, end), and End events of last step's
  // contacts [old_begin, old_end): both lists are sorted by key (collide
  // sorts them), so one merge walk finds last step's contacts that are gone.
  const auto begins = [&](int begin, int end, std::vector<ContactEvent>& out) {
    for (int k = begin; k < end; ++k) {
      const Contact& c = contacts_[static_cast<size_t>(k)];
      if (!c.began || !c.enabled) continue;
      ContactEvent e = event(c, ContactEvent::Type::Begin);
      int deepest = 0;
      for (int i = 0; i < c.count; ++i)
        if (c.points[i].depth > c.points[deepest].depth) deepest = i;
      e.point = body(c.body_a).transform().apply(c.points[deepest].local_a);
      e.impulse = c.totalNormalImpulse();
      out.push_back(e);
    }
  };
  const auto ends = [&](int old_begin, int old_end, std::vector<ContactEvent>& out) {
    if (old_begin >= old_end) return;
    const std::uint64_t first = old[static_cast<size_t>(old_begin)].key();
    auto now = std::partition_point(contacts_.begin(), contacts_.end(), [&](const Contact& c) { return c.key() < first; });
    for (int k = old_begin; k < old_end; ++k) {
      const Contact& o = old[static_cast<size_t>(k)];
      while (now != contacts_.end() && now->key() < o.key()) ++now;
      if (!o.touching || !o.enabled || (now != contacts_.end() && now->key() == o.key())) continue;
      out.push_back(event(o, ContactEvent::Type::End));
    }
  };
  // Each walk only where collide did not find it empty: no contact began,
  // or every one of last step's continues (most steps of a scene in
  // motion). On the pool's threads when the lists are long, each thread's
  // events kept apart and joined in range order: the order of one
  // thread's walks.
  const int n = ctx.some_began ? static_cast<int>(contacts_.size()) : 0;
  const int n_old = ctx.all_continued ? 0 : static_cast<int>(old.size());
  ctx.some_began = true;  // unknown until the next collide
  ctx.all_continued = false;
  std::vector<ContactEvent>& events = w.contact_events_;
  if (w.pool_ && n + n_old >= kParallelContacts) {
    const auto threads = static_cast<size_t>(w.pool_->threads());
    ctx.begin_events.resize(threads);
    ctx.end_events.resize(threads);
    w.pool_->parallelFor(w.pool_->threads(), [&](int t0, int t1) {
      for (int t = t0; t < t1; ++t) {
        const auto T = static_cast<std::int64_t>(threads);
        std::vector<ContactEvent>& b = ctx.begin_events[static_cast<size_t>(t)];
        std::vector<ContactEvent>& e = ctx.end_events[static_cast<size_t>(t)];
        b.clear();
        e.clear();
        begins(static_cast<int>(t * n / T), static_cast<int>((t + 1) * n / T), b);
        ends(static_cast<int>(t * n_old / T), static_cast<int>((t + 1) * n_old / T), e);
      }
    });
    for (const std::vector<ContactEvent>& b : ctx.begin_events) events.insert(events.end(), b.begin(), b.end());
    for (const std::vector<ContactEvent>& e : ctx.end_events) events.insert(events.end(), e.begin(), e.end());
  } else {
    begins(0, n, events);
    ends(0, n_old, events);
  }
  for (const Contact& o : w.ended_contacts_)
    if (o.touching && o.enabled) events.push_back(event(o, ContactEvent::Type::End));
  w.ended_contacts_.clear();
}

}  // namespace cairn::detail
