// Dynamic AABB tree and broadphase pairs against brute force.
#include "collision/broadphase.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

namespace cairn {
namespace {

Aabb randomBox(std::mt19937& rng, Real world, Real max_half) {
  std::uniform_real_distribution<Real> c(-world, world), h(0.05, max_half);
  return Aabb::fromCenterHalf(Vec3(c(rng), c(rng), c(rng)), Vec3(h(rng), h(rng), h(rng)));
}

TEST(BroadPhaseTree, StaysValidAndBalancedUnderRandomInsertRemoveUpdate) {
  std::mt19937 rng(1);
  DynamicTree tree;
  std::vector<int> leaves;
  for (int step = 0; step < 3000; ++step) {
    const int op = std::uniform_int_distribution<int>(0, 9)(rng);
    if (leaves.empty() || op < 5) {
      leaves.push_back(tree.insert(randomBox(rng, 20, 1), step));
    } else if (op < 7) {
      const size_t k = std::uniform_int_distribution<size_t>(0, leaves.size() - 1)(rng);
      tree.remove(leaves[k]);
      leaves.erase(leaves.begin() + k);
    } else {
      const size_t k = std::uniform_int_distribution<size_t>(0, leaves.size() - 1)(rng);
      tree.update(leaves[k], randomBox(rng, 20, 1));
    }
    ASSERT_TRUE(tree.validate()) << "step " << step;
  }
  // AVL balance: height <= 1.44 log2(n + 2).
  const Real n = static_cast<Real>(tree.leafCount());
  EXPECT_LE(tree.height(), 1.44 * std::log2(n + 2)) << n << " leaves";
}

// Sorted list of all overlapping pairs of fat boxes, the O(n^2) way.
std::vector<std::pair<int, int>> bruteForcePairs(const BroadPhase& bp, const std::vector<int>& handles) {
  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < handles.size(); ++i)
    for (size_t j = i + 1; j < handles.size(); ++j) {
      const int a = handles[i], b = handles[j];
      if (bp.isInfinite(a) && bp.isInfinite(b)) continue;
      if (bp.fatAabb(a).overlaps(bp.fatAabb(b))) pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

TEST(BroadPhasePairs, MatchBruteForceOnRandomOverlappingSetsThroughMovesAndRemovals) {
  std::mt19937 rng(42);
  BroadPhase bp(0.1);
  std::vector<int> handles;
  std::vector<Aabb> tight;
  for (int i = 0; i < 400; ++i) {
    tight.push_back(randomBox(rng, 6, 0.8));  // dense: many overlaps
    handles.push_back(bp.createProxy(tight.back(), i));
  }
  // Two planes: infinite boxes that pair with every finite proxy.
  handles.push_back(bp.createProxy(Aabb{Vec3::Constant(-kInf), Vec3(kInf, 0, kInf)}, 1000));
  handles.push_back(bp.createProxy(Aabb{Vec3::Constant(-kInf), Vec3::Constant(kInf)}, 1001));
  std::vector<std::pair<int, int>> pairs;
  std::uniform_real_distribution<Real> step(-0.2, 0.2);
  for (int frame = 0; frame < 30; ++frame) {
    bp.updatePairs(pairs);
    const auto expected = bruteForcePairs(bp, handles);
    ASSERT_EQ(pairs, expected) << "frame " << frame;
    ASSERT_TRUE(bp.tree().validate());
    for (const auto& [a, b] : pairs) ASSERT_LT(a, b);
    // Move every finite proxy a little, destroy and create a few.
    for (size_t k = 0; k + 2 < handles.size(); ++k) {
      const Vec3 d(step(rng), step(rng), step(rng));
      tight[k] = Aabb{tight[k].lo + d, tight[k].hi + d};
      bp.moveProxy(handles[k], tight[k], d);
    }
    for (int r = 0; r < 5; ++r) {
      const size_t k = std::uniform_int_distribution<size_t>(0, handles.size() - 3)(rng);
      bp.destroyProxy(handles[k]);
      tight[k] = randomBox(rng, 6, 0.8);
      handles[k] = bp.createProxy(tight[k], static_cast<int>(k));
    }
  }
  // Tight boxes never leave their fat boxes: the proxies' contract.
  for (size_t k = 0; k + 2 < handles.size(); ++k) EXPECT_TRUE(bp.fatAabb(handles[k]).contains(tight[k]));
}

// The moved proxies' queries split into parts (as the World's threads run
// them) find what one pass finds: the same pairs, the same capped proxies
// in the same order, the same count of box tests, whatever the split and
// in whatever order the parts run. Dense boxes and a cap of 6 pairs a
// query, so that queries are cut short.
TEST(BroadPhasePairs, QueriesSplitIntoPartsFindWhatOnePassFinds) {
  std::mt19937 rng(7);
  BroadPhase whole(0.1), split(0.1);
  std::vector<int> handles;
  for (int i = 0; i < 300; ++i) {
    const Aabb box = randomBox(rng, 4, 0.8);
    handles.push_back(whole.createProxy(box, i));
    ASSERT_EQ(split.createProxy(box, i), handles.back());
  }
  whole.createProxy(Aabb{Vec3::Constant(-kInf), Vec3(kInf, 0, kInf)}, 1000);  // a plane: never capped
  split.createProxy(Aabb{Vec3::Constant(-kInf), Vec3(kInf, 0, kInf)}, 1000);
  for (BroadPhase* bp : {&whole, &split}) bp->setMaxPairsPerProxy(6);
  std::uniform_real_distribution<Real> step(-0.3, 0.3);
  for (int frame = 0; frame < 10; ++frame) {
    const int parts = 1 + frame % 4;  // 1 to 4 parts, run last to first
    std::vector<std::pair<int, int>> a, b;
    whole.resetOverlapTests();
    split.resetOverlapTests();
    const bool changed_a = whole.updatePairs(a);
    const bool changed_b = split.updatePairs(b, parts, [&](int n, auto&& query) {
      for (int k = parts; k-- > 0;) query(k, k * n / parts, (k + 1) * n / parts);
    });
    ASSERT_EQ(changed_a, changed_b) << "frame " << frame;
    ASSERT_EQ(a, b) << "frame " << frame;
    ASSERT_EQ(whole.cappedProxies(), split.cappedProxies()) << "frame " << frame;
    ASSERT_FALSE(whole.cappedProxies().empty()) << "frame " << frame;
    ASSERT_EQ(whole.overlapTests(), split.overlapTests()) << "frame " << frame;
    for (size_t k = 0; k < handles.size(); k += 2) {  // half of them move
      const Vec3 d(step(rng), step(rng), step(rng));
      const Aabb box{whole.fatAabb(handles[k]).lo + d, whole.fatAabb(handles[k]).hi + d};
      whole.moveProxy(handles[k], box, d);
      split.moveProxy(handles[k], box, d);
    }
  }
}

// n unit boxes on a grid with gaps wider than the fat margins: no pairs, and
// finding that must cost O(n log n) box tests, not n^2 / 2.
std::uint64_t gridPairTests(int side, std::vector<std::pair<int, int>>& pairs) {
  BroadPhase bp(0.1);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < 10; ++k)
        bp.createProxy(Aabb::fromCenterHalf(Vec3(3.0 * i, 3.0 * k, 3.0 * j), Vec3::Constant(0.5)), (i * side + j) * 10 + k);
  bp.resetOverlapTests();
  bp.updatePairs(pairs);
  return bp.overlapTests();
}

TEST(BroadPhasePairs, GridOfThousandSeparatedBoxesCostsNLogNTests) {
  std::vector<std::pair<int, int>> pairs;
  const std::uint64_t tests_1000 = gridPairTests(10, pairs);  // 10 x 10 x 10
  EXPECT_TRUE(pairs.empty());
  const Real n = 1000;
  // Each query descends the O(log n) path to its own leaf and tests both
  // children at every level: about 2 log2 n tests. Inner boxes of a grid
  // also cover the gaps next to their cells, so a query enters a few
  // neighbouring subtrees too (measured: 3.8 n log2 n). C = 5.
  const Real c = 5;
  EXPECT_LT(static_cast<Real>(tests_1000), c * n * std::log2(n)) << tests_1000;
  EXPECT_LT(static_cast<Real>(tests_1000), 0.1 * n * n / 2) << tests_1000;
  // Growth: 4x the bodies costs about 4x (log 4000 / log 1000 = 1.2) as many
  // tests, nowhere near the 16x of a quadratic method.
  const std::uint64_t tests_4000 = gridPairTests(20, pairs);  // 20 x 20 x 10
  EXPECT_TRUE(pairs.empty());
  const Real ratio = static_cast<Real>(tests_4000) / static_cast<Real>(tests_1000);
  EXPECT_LT(ratio, 4 * 1.2 * 1.25) << tests_1000 << " -> " << tests_4000;
  std::printf("grid pair tests: n=1000 %llu (%.2f n log2 n), n=4000 %llu\n", (unsigned long long)tests_1000,
              tests_1000 / (n * std::log2(n)), (unsigned long long)tests_4000);
}

TEST(BroadPhasePairs, SlowProxyInsideItsFatBoxIsNotReinserted) {
  BroadPhase bp(0.1);
  const Aabb box = Aabb::fromCenterHalf(Vec3::Zero(), Vec3::Constant(0.5));
  const int h = bp.createProxy(box, 7);
  std::vector<std::pair<int, int>> pairs;
  bp.updatePairs(pairs);
  const Vec3 small(0.05, 0, 0);
  EXPECT_FALSE(bp.moveProxy(h, Aabb{box.lo + small, box.hi + small}));
  const Vec3 big(0.2, 0, 0);
  EXPECT_TRUE(bp.moveProxy(h, Aabb{box.lo + big, box.hi + big}));
  // Predicted displacement stretches the fat box forward only.
  EXPECT_TRUE(bp.moveProxy(h, Aabb{box.lo + Vec3(1, 0, 0), box.hi + Vec3(1, 0, 0)}, Vec3(0.5, 0, 0)));
  EXPECT_NEAR(bp.fatAabb(h).hi.x(), 1.5 + 0.1 + 2 * 0.5, 1e-12);
  EXPECT_NEAR(bp.fatAabb(h).lo.x(), 0.5 - 0.1, 1e-12);
  EXPECT_EQ(bp.user(h), 7);
}

// Filter bits (Bullet's group/mask rule): overlapping proxies pair only when
// each one's group meets the other's mask, and a changed filter re-pairs at
// the next update without the proxies moving.
TEST(BroadPhasePairs, FilterBitsDecideWhichOverlapsPair) {
  BroadPhase bp(0.1);
  const Aabb box = Aabb::fromCenterHalf(Vec3::Zero(), Vec3::Constant(0.5));
  const int a = bp.createProxy(box, 0), b = bp.createProxy(box, 1), c = bp.createProxy(box, 2);
  bp.setFilter(a, 1, ~2u);  // a ignores group 2
  bp.setFilter(b, 2, ~0u);  // b would take anyone
  std::vector<std::pair<int, int>> pairs;
  bp.updatePairs(pairs);
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{a, c}, {b, c}}));
  EXPECT_FALSE(bp.updatePairs(pairs));  // nothing changed
  bp.setFilter(a, 1, ~0u);
  EXPECT_TRUE(bp.updatePairs(pairs));
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{a, b}, {a, c}, {b, c}}));
  bp.setFilter(c, 4, 4);  // c only with group 4: nobody
  bp.updatePairs(pairs);
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{a, b}}));
}

// A proxy whose filter meets no live proxy's cannot pair: its query is not
// run at all (no box test is counted), and the answer follows the proxies
// that come, go and change their filters.
// A chain's 20 links: group 2, every mask bit but 2's, side by side 0.5
// apart along x (boxes of half size 0.4).
std::vector<int> addChainLinks(BroadPhase& bp) {
  std::vector<int> links;
  for (int i = 0; i < 20; ++i) {
    links.push_back(bp.createProxy(Aabb::fromCenterHalf(Vec3(0.5 * i, 0, 0), Vec3::Constant(0.4)), i));
    bp.setFilter(links.back(), 2, ~2u);
  }
  return links;
}

TEST(BroadPhasePairs, ProxyThatCanPairWithNothingIsNotQueried) {
  BroadPhase bp(0.1);
  std::vector<std::pair<int, int>> pairs;
  const std::vector<int> links = addChainLinks(bp);
  bp.resetOverlapTests();
  bp.updatePairs(pairs);
  EXPECT_TRUE(pairs.empty());
  EXPECT_EQ(bp.overlapTests(), 0u);
  EXPECT_FALSE(bp.mayPairWithAny(2, ~2u));
  // A ball of group 1 that takes everything: the links may now pair with it.
  const int ball = bp.createProxy(Aabb::fromCenterHalf(Vec3(0, 0.5, 0), Vec3::Constant(0.3)), 99);
  EXPECT_TRUE(bp.mayPairWithAny(2, ~2u));
  bp.updatePairs(pairs);
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{links[0], ball}, {links[1], ball}}));
  // Gone again: exact after the next update, and a moved link is not queried.
  bp.destroyProxy(ball);
  bp.updatePairs(pairs);
  EXPECT_TRUE(pairs.empty());
  EXPECT_FALSE(bp.mayPairWithAny(2, ~2u));
  bp.resetOverlapTests();
  bp.moveProxy(links[3], Aabb::fromCenterHalf(Vec3(9, 0, 0), Vec3::Constant(0.4)));
  bp.updatePairs(pairs);
  EXPECT_EQ(bp.overlapTests(), 0u);
  // A link refiltered to meet the others' group pairs with its neighbours.
  bp.setFilter(links[10], 2, ~0u);
  EXPECT_TRUE(bp.mayPairWithAny(2, ~0u));
  bp.updatePairs(pairs);
  EXPECT_TRUE(pairs.empty());  // the others' masks still refuse group 2
  bp.setFilter(links[10], 1, ~0u);
  bp.updatePairs(pairs);
  // Fat boxes (half 0.4 + margin 0.1, 0.5 apart) reach two neighbours each way.
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{
                       {links[8], links[10]}, {links[9], links[10]}, {links[10], links[11]}, {links[10], links[12]}}));
}

// Links that can pair with nothing leave the tree at their next move (no
// reinsertion however far they go), yet box queries and ray casts still
// find them; a proxy that gives them something to pair with brings them
// back into the tree and into the pairs.
TEST(BroadPhasePairs, ProxiesThatCanPairWithNothingLeaveTheTreeAndQueriesStillFindThem) {
  BroadPhase bp(0.1);
  std::vector<std::pair<int, int>> pairs;
  const std::vector<int> links = addChainLinks(bp);
  bp.updatePairs(pairs);
  // Each link moves far (a whipping chain): out of the tree, into the list.
  for (int i = 0; i < 20; ++i)
    bp.moveProxy(links[static_cast<size_t>(i)], Aabb::fromCenterHalf(Vec3(0.5 * i, 3, 0), Vec3::Constant(0.4)));
  EXPECT_EQ(bp.tree().leafCount(), 0);
  EXPECT_EQ(bp.loners().size(), 20u);
  ASSERT_TRUE(bp.tree().validate());
  // A box query over x in [1.9, 3.1] meets links 3 to 7 (fat half 0.5).
  std::vector<int> hit;
  bp.query(Aabb::fromCenterHalf(Vec3(2.5, 3, 0), Vec3(0.6, 0.1, 0.1)), [&](int h) {
    hit.push_back(h);
    return true;
  });
  std::sort(hit.begin(), hit.end());
  EXPECT_EQ(hit, (std::vector<int>{links[3], links[4], links[5], links[6], links[7]}));
  // A ray along the row meets every link's box; one below it meets none.
  int along = 0, below = 0;
  bp.rayCast(Vec3(-1, 3, 0), Vec3(20, 0, 0), 1, Vec3::Zero(), [&](int, Real f) {
    ++along;
    return f;
  });
  bp.rayCast(Vec3(-1, 0, 0), Vec3(20, 0, 0), 1, Vec3::Zero(), [&](int, Real f) {
    ++below;
    return f;
  });
  EXPECT_EQ(along, 20);
  EXPECT_EQ(below, 0);
  // A ball of group 1 that takes everything: the links come back and pair.
  const int ball = bp.createProxy(Aabb::fromCenterHalf(Vec3(0, 3.5, 0), Vec3::Constant(0.3)), 99);
  bp.updatePairs(pairs);
  EXPECT_TRUE(bp.loners().empty());
  EXPECT_EQ(bp.tree().leafCount(), 21);
  EXPECT_EQ(pairs, (std::vector<std::pair<int, int>>{{links[0], ball}, {links[1], ball}}));
  ASSERT_TRUE(bp.tree().validate());
}

}  // namespace
}  // namespace cairn
