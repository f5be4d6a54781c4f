// The cursor's lower bound (world/sorted_keys.hpp) against std::lower_bound
// over the whole list: the same index for every key and every cursor, on
// lists with runs of equal keys, gaps, keys below the first and above the
// last, and in the orders collide searches them (ascending, mostly, with
// steps back).
#include "world/sorted_keys.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace cairn::detail {
namespace {

std::size_t wholeListLowerBound(const std::vector<std::uint64_t>& keys, std::uint64_t key) {
  return static_cast<std::size_t>(std::lower_bound(keys.begin(), keys.end(), key) - keys.begin());
}

TEST(SortedKeys, LowerBoundFromAnyCursorIsTheWholeListsLowerBound) {
  std::mt19937_64 rng(11);
  for (const std::size_t n : {0, 1, 2, 3, 7, 64, 1000}) {
    std::vector<std::uint64_t> keys(n);
    for (std::uint64_t& k : keys) k = 10 + 2 * (rng() % (n + 1));  // even, with repeats: odd keys fall between
    std::sort(keys.begin(), keys.end());
    for (std::uint64_t key = 0; key <= 10 + 2 * (n + 2); ++key)
      for (std::size_t start = 0; start <= n + 2; start += (n > 64 ? 37 : 1)) {
        std::size_t cursor = start;  // past the end included: it is clamped
        const std::size_t got = lowerBoundFrom(keys, key, cursor);
        ASSERT_EQ(got, wholeListLowerBound(keys, key)) << "n " << n << " key " << key << " cursor " << start;
        EXPECT_EQ(cursor, got);
      }
  }
}

// Keys looked up one after another, the cursor carried, in a mostly
// ascending order with steps back and long jumps: each answer is the whole
// list's.
TEST(SortedKeys, ACarriedCursorFollowsAMostlyAscendingWalk) {
  std::mt19937_64 rng(5);
  std::vector<std::uint64_t> keys(15000);
  for (std::uint64_t& k : keys) k = rng() % 100000;
  std::sort(keys.begin(), keys.end());
  std::size_t cursor = 0;
  std::uint64_t key = 0;
  for (int i = 0; i < 20000; ++i) {
    const std::uint64_t r = rng() % 100;
    if (r < 80) key += rng() % 12;                   // a few keys on
    else if (r < 90) key -= std::min<std::uint64_t>(key, rng() % 50);  // a step back
    else key = rng() % 110000;                       // anywhere, past the last key included
    ASSERT_EQ(lowerBoundFrom(keys, key, cursor), wholeListLowerBound(keys, key)) << "lookup " << i << " key " << key;
  }
}

}  // namespace
}  // namespace cairn::detail
