// Broadphase proxies and incremental pair maintenance (see broadphase.hpp).
#include "collision/broadphase.hpp"

#include <algorithm>
#include <iterator>

namespace cairn {

Aabb BroadPhase::fatten(const Aabb& tight, const Vec3& displacement) const {
  Aabb fat = tight.expanded(margin_);
  const Vec3 d = displacement_multiplier_ * displacement;
  // Stretch only toward where the body is heading.
  fat.lo += d.cwiseMin(Vec3::Zero());
  fat.hi += d.cwiseMax(Vec3::Zero());
  return fat;
}

void BroadPhase::markMoved(int h) {
  Proxy& p = proxies_[h];
  if (!p.moved) {
    p.moved = true;
    moved_.push_back(h);
  }
  if (!p.dirty) {
    p.dirty = true;
    dirty_.push_back(h);
  }
}

void BroadPhase::leaveTree(int h) {
  Proxy& p = proxies_[h];
  tree_.remove(p.leaf);
  p.leaf = -1;
  p.loner = true;
  loners_.insert(std::lower_bound(loners_.begin(), loners_.end(), h), h);
}

void BroadPhase::enterTree(int h) {
  Proxy& p = proxies_[h];
  loners_.erase(std::lower_bound(loners_.begin(), loners_.end(), h));
  p.loner = false;
  p.leaf = tree_.insert(p.fat, h);
  markMoved(h);  // to be queried for the pairs it may now have
}

int BroadPhase::createProxy(const Aabb& tight, int user, const Vec3& displacement, int owner) {
  int h;
  if (free_ >= 0) {
    h = free_;
    free_ = proxies_[h].next_free;
  } else {
    h = static_cast<int>(proxies_.size());
    proxies_.emplace_back();
  }
  Proxy& p = proxies_[h];
  // A reused handle may still own stale pairs and a place in moved_.
  const bool dirty = p.dirty, moved = p.moved;
  p = Proxy{};
  p.dirty = dirty;
  p.moved = moved;
  p.alive = true;
  p.user = user;
  p.owner = owner;
  addFilter(p.group, p.mask);
  if (tight.isInfinite()) {
    p.fat = tight;
    p.infinite = true;
    infinite_.insert(std::lower_bound(infinite_.begin(), infinite_.end(), h), h);
  } else {
    p.fat = fatten(tight, displacement);
    p.leaf = tree_.insert(p.fat, h);
  }
  ++live_;
  markMoved(h);
  return h;
}

void BroadPhase::destroyProxy(int h) {
  Proxy& p = proxies_[h];
  if (!p.alive) return;
  if (p.leaf >= 0) tree_.remove(p.leaf);
  else if (p.loner) loners_.erase(std::lower_bound(loners_.begin(), loners_.end(), h));
  else infinite_.erase(std::lower_bound(infinite_.begin(), infinite_.end(), h));
  if (!p.dirty) {
    p.dirty = true;
    dirty_.push_back(h);
  }
  p.alive = false;
  p.leaf = -1;
  p.loner = false;
  filters_stale_ = true;
  p.next_free = free_;
  free_ = h;
  --live_;
}

bool BroadPhase::moveProxy(int h, const Aabb& tight, const Vec3& displacement) {
  if (!moveChanges(h, tight, displacement)) return false;
  Proxy& p = proxies_[h];
  if (p.infinite) {
    // An infinite proxy (a plane) keeps the box it is given: a moved plane's
    // half-space bounds something else.
    p.fat = tight;
    markMoved(h);
    return true;
  }
  const Aabb want = fatten(tight, displacement);
  if (!p.loner && !mayPairWithAny(p.group, p.mask)) leaveTree(h);
  if (p.loner) {
    // Out of the tree: its box is only read by queries, tested one by one.
    p.fat = want;
    return false;
  }
  p.fat = want;
  tree_.update(p.leaf, want);
  markMoved(h);
  return true;
}

bool BroadPhase::outgrown(const Proxy& p, const Aabb& tight, const Aabb& want) const {
  if (!p.fat.contains(tight)) return true;
  // A fat box far larger than wanted (the body slowed down) costs false
  // pairs; shrink it once it overhangs by more than four margins.
  const Real slack = 4 * margin_;
  return ((p.fat.hi - want.hi).array() > slack).any() || ((want.lo - p.fat.lo).array() > slack).any();
}

// What moveProxy would do, decided without doing it (moveProxy acts on it).
bool BroadPhase::moveChanges(int h, const Aabb& tight, const Vec3& displacement) const {
  const Proxy& p = proxies_[h];
  if (p.infinite) return !(p.fat.lo == tight.lo && p.fat.hi == tight.hi);
  if (p.loner || !mayPairWithAny(p.group, p.mask)) return true;  // a loner's box is set; a proxy leaves the tree
  return outgrown(p, tight, fatten(tight, displacement));
}

void BroadPhase::setFilter(int h, std::uint32_t group, std::uint32_t mask) {
  Proxy& p = proxies_[h];
  if (p.group == group && p.mask == mask) return;
  p.group = group;
  p.mask = mask;
  addFilter(group, mask);
  filters_stale_ = true;
  markMoved(h);
}

std::vector<BroadPhase::ProxyState> BroadPhase::proxyStates() const {
  std::vector<ProxyState> out;
  out.reserve(proxies_.size());
  for (const Proxy& p : proxies_) out.push_back({p.fat, p.user, p.owner, p.next_free, p.alive});
  return out;
}

void BroadPhase::restore(const std::vector<ProxyState>& proxies, int free_head) {
  *this = BroadPhase(margin_, displacement_multiplier_);
  proxies_.resize(proxies.size());
  for (size_t i = 0; i < proxies.size(); ++i) {
    const int h = static_cast<int>(i);
    Proxy& p = proxies_[i];
    p.fat = proxies[i].fat;
    p.user = proxies[i].user;
    p.owner = proxies[i].owner;
    p.next_free = proxies[i].next_free;
    p.alive = proxies[i].alive;
    if (!p.alive) continue;
    ++live_;
    addFilter(p.group, p.mask);
    if (p.fat.isInfinite()) {
      p.infinite = true;
      infinite_.push_back(h);
    } else {
      p.leaf = tree_.insert(p.fat, h);
    }
    markMoved(h);
  }
  free_ = free_head;
}

bool BroadPhase::updatePairs(std::vector<std::pair<int, int>>& out) {
  const int moved = startPairUpdate();
  PairQueries& q = queryPart(0);
  q.clear();
  queryMoved(0, moved, q);
  return finishPairUpdate(1, out);
}

int BroadPhase::startPairUpdate() {
  changed_ = !moved_.empty() || !dirty_.empty();
  if (filters_stale_) {
    group_union_ = mask_union_ = 0;
    for (const Proxy& p : proxies_)
      if (p.alive) addFilter(p.group, p.mask);
    filters_stale_ = false;
  }
  // Loners that a new or refiltered proxy gave something to pair with go
  // back into the tree, to be queried below.
  for (size_t k = loners_.size(); k-- > 0;) {
    const int h = loners_[k];
    if (mayPairWithAny(proxies_[h].group, proxies_[h].mask)) enterTree(h);
  }
  return static_cast<int>(moved_.size());
}

BroadPhase::PairQueries& BroadPhase::queryPart(int part) {
  if (query_parts_.size() <= static_cast<size_t>(part)) query_parts_.resize(static_cast<size_t>(part) + 1);
  return query_parts_[static_cast<size_t>(part)];
}

// 1. Pairs found by querying each moved proxy. A query stops at max_pairs_
//    other proxies (the bound in the header). A pair of two moved proxies
//    may be found twice (the sort below keeps one): keeping it from one
//    side only would lose it whenever that side's query was the one cut
//    short (a ground box under 900 new boxes).
void BroadPhase::queryMoved(int begin, int end, PairQueries& q) const {
  for (int k = begin; k < end; ++k) {
    const int m = moved_[static_cast<size_t>(k)];
    const Proxy& pm = proxies_[m];
    // A proxy whose filter meets no live proxy's has no pair to find
    // (the pair test below would reject every overlap).
    if (!pm.alive || !mayPairWithAny(pm.group, pm.mask)) continue;
    int found = 0;
    auto add = [&](int o) {
      const Proxy& po = proxies_[o];
      if (o == m || (pm.owner >= 0 && po.owner == pm.owner)) return true;
      if ((pm.group & po.mask) == 0 || (po.group & pm.mask) == 0) return true;
      q.fresh.emplace_back(std::min(m, o), std::max(m, o));
      if (pm.infinite || po.infinite || ++found < max_pairs_) return true;
      q.capped.push_back(m);
      return false;
    };
    if (pm.infinite) {
      // Infinite: tested against every finite proxy (an axis-aligned
      // plane's box still rules out what lies wholly above it).
      for (int o = 0; o < static_cast<int>(proxies_.size()); ++o) {
        if (!proxies_[o].alive || proxies_[o].infinite) continue;
        ++q.tests;
        if (pm.fat.overlaps(proxies_[o].fat)) add(o);
      }
    } else {
      tree_.query(pm.fat, [&](int leaf) { return add(tree_.user(leaf)); }, &q.tests);
      for (int i : infinite_) {
        ++q.tests;
        if (pm.fat.overlaps(proxies_[i].fat)) add(i);
      }
    }
  }
}

bool BroadPhase::finishPairUpdate(int parts, std::vector<std::pair<int, int>>& out) {
  // The parts' finds, in the order of their ranges: the order one query
  // after another would have found them in.
  std::vector<std::pair<int, int>>& fresh = query_parts_[0].fresh;
  std::swap(capped_, query_parts_[0].capped);
  overlap_tests_ += query_parts_[0].tests;
  for (size_t k = 1; k < static_cast<size_t>(parts); ++k) {
    const PairQueries& q = query_parts_[k];
    fresh.insert(fresh.end(), q.fresh.begin(), q.fresh.end());
    capped_.insert(capped_.end(), q.capped.begin(), q.capped.end());
    overlap_tests_ += q.tests;
  }
  // 2. Drop the stale pairs of proxies that moved or died, add the fresh.
  if (!dirty_.empty()) {
    pairs_.erase(std::remove_if(pairs_.begin(), pairs_.end(),
                                [&](const std::pair<int, int>& pr) {
                                  return proxies_[pr.first].dirty || proxies_[pr.second].dirty;
                                }),
                 pairs_.end());
  }
  // pairs_ stays sorted and unique between calls: sort only what is new
  // and merge it in (a scene at rest adds nothing and sorts nothing).
  if (!fresh.empty()) {
    std::sort(fresh.begin(), fresh.end());
    merged_.clear();  // std::inplace_merge would allocate a buffer each call
    std::merge(pairs_.begin(), pairs_.end(), fresh.begin(), fresh.end(), std::back_inserter(merged_));
    std::swap(pairs_, merged_);
    pairs_.erase(std::unique(pairs_.begin(), pairs_.end()), pairs_.end());
  }

  for (int h : moved_) proxies_[h].moved = false;
  for (int h : dirty_) proxies_[h].dirty = false;
  moved_.clear();
  dirty_.clear();
  out.assign(pairs_.begin(), pairs_.end());
  return changed_;
}

}  // namespace cairn
