// Broadphase: which shapes might touch, from their bounding boxes.
//
// Each proxy stores a fat box: its tight box grown by a margin on every side
// and stretched along the displacement predicted for the next step
//   fat = expand(tight, margin) u (expand(tight, margin) + k * displacement)
// (k = displacement_multiplier, e.g. 2 * v * dt). A moving proxy is
// re-inserted into the tree only when its tight box leaves the fat box (or
// the fat box has grown far larger than needed), so a slow body costs
// nothing most steps.
//
// Pairs are pairs of fat boxes that overlap. They are kept between updates:
// a pair can only change when one of its proxies got a new fat box, so
// updatePairs() re-queries just the proxies that moved (O(m log n) box tests
// for m moved proxies) and merges the result into the sorted pair list.
//
// Infinite shapes (planes: an unbounded box) never enter the tree; they sit
// in a list and are tested against every finite proxy (a tilted plane's box
// is all of space and pairs with everything; an axis-aligned one still
// excludes what lies wholly on its outer side). Two infinite proxies never
// pair (static planes cannot collide).
//
// Proxies are addressed by int handles (reused after destroyProxy) and carry
// a user int, e.g. the shape index, and an owner, e.g. the body: proxies of
// one owner never pair, so the shapes of one body never enter the pair list
// (10,000 coincident shapes of one body once made 50 million pairs that
// were all filtered out later, 1.19 GB).
//
// Collision filter bits (setFilter): two proxies pair only if each one's
// group meets the other's mask, the rule of Bullet's
// btOverlapFilterCallback (m_collisionFilterGroup / m_collisionFilterMask)
// and Box2D's b2ShouldShapesCollide, applied where the pair is found: a
// chain whose links never collide with each other makes no pairs to sort,
// keep and hand to the narrowphase only to be thrown away there.
//
// Proxies that can pair with nothing (a chain's links whose filter meets
// no live proxy's, mayPairWithAny) are kept out of the tree, in a sorted
// list that queries and ray casts test one by one as they test infinite
// proxies: such a proxy moves every step and, fast, leaves its fat box
// most steps, and a tree reinsertion costs a descent and the refits above
// it for a box that no pair search will ever ask about. A proxy enters
// the list at its next move once it can pair with nothing, and goes back
// into the tree (to be queried for pairs) at the updatePairs after a new
// or refiltered proxy gives it something to pair with.
//
// Bounded pairs: one proxy's query stops after max_pairs_per_proxy other
// proxies (setMaxPairsPerProxy), so the pair list holds at most that many
// pairs per finite proxy whatever the scene (N coincident boxes make
// N max pairs at most, not N (N - 1) / 2). A pair stays in the list only
// while neither proxy moves, so every listed pair was found by the latest
// query of one of its proxies, and each query keeps at most the maximum:
// the bound holds across updates. A pair is kept when either side's query
// found it, so a large proxy whose own query was cut short (a ground box
// under many bodies) still pairs with every small proxy that queried it.
// Which overlaps a capped query keeps follows the tree's order:
// deterministic. cappedProxies() names the
// proxies whose query stopped early in the last update. Infinite proxies
// (planes) are not capped: they are few, and a ground plane under 10,000
// boxes must pair with all of them.
#pragma once

#include "collision/aabb.hpp"
#include "collision/dynamic_tree.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace cairn {

class BroadPhase {
 public:
  // margin: how far every fat box reaches beyond its tight box (length).
  // displacement_multiplier: how many predicted displacements to extend it.
  explicit BroadPhase(Real margin = Real(0.05), Real displacement_multiplier = Real(2))
      : margin_(margin), displacement_multiplier_(displacement_multiplier) {}

  // tight: the shape's current world box; displacement: its predicted
  // motion over the next step (v * dt), zero for static shapes.
  // owner: proxies with the same owner >= 0 never pair (-1: pairs with all).
  int createProxy(const Aabb& tight, int user, const Vec3& displacement = Vec3::Zero(), int owner = -1);
  void destroyProxy(int handle);
  // Returns true when the fat box changed (the proxy was re-inserted). An
  // infinite proxy takes `tight` as it is.
  bool moveProxy(int handle, const Aabb& tight, const Vec3& displacement = Vec3::Zero());
  // Whether moveProxy with these arguments would change anything (a box
  // kept, a proxy left out of the tree, a fat box re-inserted). It only
  // reads, so threads may ask it for many proxies at once and hand the few
  // that change to moveProxy one after another.
  bool moveChanges(int handle, const Aabb& tight, const Vec3& displacement = Vec3::Zero()) const;
  // Collision filter of a proxy (default: group 1, every mask bit set).
  // A change re-pairs the proxy at the next updatePairs.
  void setFilter(int handle, std::uint32_t group, std::uint32_t mask);
  // Whether a proxy with this filter could pair with any live proxy: its
  // mask meets some proxy's group and its group some proxy's mask. Kept as
  // the union of every live filter (a superset between updatePairs calls,
  // exact after one), so a false answer is always safe: a chain whose links
  // collide with nothing queries no tree for pairs it would throw away.
  bool mayPairWithAny(std::uint32_t group, std::uint32_t mask) const {
    return (mask & group_union_) != 0 && (group & mask_union_) != 0;
  }

  // Every pair of proxies whose fat boxes overlap, each once as (lo, hi)
  // handles with lo < hi, sorted. `out` is overwritten. Returns false when
  // no proxy moved, was created or died since the last call: the pairs are
  // the last call's.
  bool updatePairs(std::vector<std::pair<int, int>>& out);

  // The same, with the queries of the proxies that moved split among
  // threads: forRanges(n, fn) must call fn(part, begin, end) for `parts`
  // contiguous ranges of [0, n) in ascending order of part (part k's
  // range before part k + 1's; parts left out count as empty), at once or
  // one after another. The queries only read the broadphase, and the
  // parts' finds are joined in the order of their ranges: the pairs,
  // cappedProxies() and overlapTests() are those of updatePairs, whatever
  // the split.
  template <class ForRanges>
  bool updatePairs(std::vector<std::pair<int, int>>& out, int parts, ForRanges&& for_ranges) {
    const int moved = startPairUpdate();
    for (int k = 0; k < parts; ++k) queryPart(k).clear();  // made, and emptied, before the threads run
    for_ranges(moved, [this](int part, int begin, int end) { queryMoved(begin, end, query_parts_[static_cast<size_t>(part)]); });
    return finishPairUpdate(parts, out);
  }

  // The broadphase as plain data (snapshots, world/snapshot_state.cpp):
  // per handle its fat box, user, owner, liveness and free-list link, and the head
  // of the free list. restore() rebuilds from that: the same handles, fat
  // boxes and free list, a tree built by inserting the live finite proxies
  // in handle order, and every live proxy queued for updatePairs, which so
  // finds exactly the pairs of overlapping fat boxes the original held.
  // The tree's shape may differ, which no result depends on (pairs and
  // query answers are sorted).
  struct ProxyState {
    Aabb fat;
    int user = -1;
    int owner = -1;
    int next_free = -1;
    bool alive = false;
  };
  std::vector<ProxyState> proxyStates() const;
  int freeHead() const { return free_; }
  void restore(const std::vector<ProxyState>& proxies, int free_head);
  // Other proxies one query may pair with (>= 1; default 64).
  void setMaxPairsPerProxy(int n) { max_pairs_ = n < 1 ? 1 : n; }
  int maxPairsPerProxy() const { return max_pairs_; }
  // Handles whose query reached the maximum in the last updatePairs.
  const std::vector<int>& cappedProxies() const { return capped_; }

  int user(int handle) const { return proxies_[handle].user; }
  const Aabb& fatAabb(int handle) const { return proxies_[handle].fat; }
  bool isInfinite(int handle) const { return proxies_[handle].infinite; }
  // Live finite proxies kept out of the tree (they can pair with nothing).
  const std::vector<int>& loners() const { return loners_; }
  int proxyCount() const { return live_; }
  const DynamicTree& tree() const { return tree_; }

  // Box-box overlap tests performed by updatePairs since the last reset.
  std::uint64_t overlapTests() const { return overlap_tests_; }
  void resetOverlapTests() { overlap_tests_ = 0; }

  // Calls visit(handle) for every proxy whose fat box overlaps `box`,
  // infinite proxies included; visit returns false to stop. Queries are
  // const and may run concurrently: they count their box tests into *tests
  // when given, not into overlapTests().
  template <class Visit>
  void query(const Aabb& box, Visit&& visit, std::uint64_t* tests = nullptr) const {
    bool go = true;
    tree_.query(box, [&](int leaf) { return go = visit(tree_.user(leaf)); }, tests);
    for (const std::vector<int>* list : {&infinite_, &loners_}) {
      for (int h : *list)
        if (go && proxies_[h].fat.overlaps(box)) go = visit(h);
      if (tests) *tests += list->size();
    }
  }

  // Calls visit(handle, max_fraction) for every proxy whose fat box, grown
  // by `extent`, meets the segment origin + f * translation, 0 <= f <=
  // max_fraction (DynamicTree::rayCast; infinite proxies first, each tested
  // against its own box). visit returns the new max_fraction, negative to
  // stop. Counts box tests into *tests when given, as query() does.
  template <class Visit>
  void rayCast(const Vec3& origin, const Vec3& translation, Real max_fraction, const Vec3& extent, Visit&& visit,
               std::uint64_t* tests = nullptr) const {
    const Vec3 inv = translation.cwiseInverse();
    for (const std::vector<int>* list : {&infinite_, &loners_}) {
      if (tests) *tests += list->size();
      for (int h : *list) {
        Real t0 = 0, t1 = max_fraction;
        if (!clipLineToBox(proxies_[h].fat.lo - extent, proxies_[h].fat.hi + extent, origin, inv, t0, t1)) continue;
        const Real f = visit(h, max_fraction);
        if (f < 0) return;
        max_fraction = std::min(max_fraction, f);
      }
    }
    tree_.rayCast(origin, translation, max_fraction, extent,
                  [&](int leaf, Real max_f) { return visit(tree_.user(leaf), max_f); }, tests);
  }

 private:
  struct Proxy {
    Aabb fat;
    int user = -1;
    int owner = -1;
    int leaf = -1;       // tree node; -1 when infinite, a loner or free
    bool infinite = false;
    bool loner = false;  // finite but kept out of the tree (loners_)
    int next_free = -1;
    bool alive = false;
    bool moved = false;  // fat box changed since the last updatePairs
    bool dirty = false;  // its pairs must be recomputed (moved or destroyed)
    std::uint32_t group = 1, mask = 0xffffffffu;  // setFilter
  };

  // What one range of the moved proxies' queries found (updatePairs).
  struct PairQueries {
    std::vector<std::pair<int, int>> fresh;
    std::vector<int> capped;
    std::uint64_t tests = 0;
    void clear() {
      fresh.clear();
      capped.clear();
      tests = 0;
    }
  };
  int startPairUpdate();  // returns how many proxies moved
  PairQueries& queryPart(int part);
  void queryMoved(int begin, int end, PairQueries& q) const;
  bool finishPairUpdate(int parts, std::vector<std::pair<int, int>>& out);

  Aabb fatten(const Aabb& tight, const Vec3& displacement) const;
  // Whether a proxy in the tree must be re-inserted with fat box `want`.
  bool outgrown(const Proxy& p, const Aabb& tight, const Aabb& want) const;
  void markMoved(int handle);
  void leaveTree(int handle);
  void enterTree(int handle);
  void addFilter(std::uint32_t group, std::uint32_t mask) {
    group_union_ |= group;
    mask_union_ |= mask;
  }

  Real margin_;
  Real displacement_multiplier_;
  DynamicTree tree_;  // leaves' user field holds the proxy handle
  std::vector<Proxy> proxies_;
  std::vector<int> infinite_;  // handles of infinite proxies, ascending
  std::vector<int> loners_;    // handles of finite proxies out of the tree, ascending
  std::vector<int> moved_;     // handles to re-query, in order of marking
  std::vector<int> dirty_;     // handles whose old pairs are stale
  std::vector<std::pair<int, int>> pairs_;
  std::vector<std::pair<int, int>> merged_;  // scratch for merging fresh pairs in
  std::vector<PairQueries> query_parts_;  // scratch for updatePairs, per part
  std::vector<int> capped_;
  bool changed_ = false;  // updatePairs' answer, from its start
  int max_pairs_ = 64;
  // OR of the live proxies' groups and masks (mayPairWithAny); a superset
  // until updatePairs recomputes them after a proxy died or was refiltered.
  std::uint32_t group_union_ = 0, mask_union_ = 0;
  bool filters_stale_ = false;
  int free_ = -1;
  int live_ = 0;
  std::uint64_t overlap_tests_ = 0;
};

}  // namespace cairn
