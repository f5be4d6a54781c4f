// A lower bound in a sorted list of keys, searched from where the last
// search ended. collide looks up each candidate pair's first contact of
// last step in last step's sorted keys (world/world_contacts.cpp), and the
// broadphase hands a thread's pairs over in the order of their keys,
// mostly: the answer is then usually a few keys on from the last one. A
// gallop from the cursor (one, two, four ... keys on, then a binary search
// in the last stride) finds it in a few probes near the keys just read,
// where a binary search over the whole list took fourteen on the 5,050-box
// pyramid's 15,000, most of them cache misses (docs/performance.md). A key
// behind the cursor (the pairs out of key order) is searched for in the
// keys before it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

namespace cairn::detail {

// The index of the first key not below `key` (keys.size() if none): what
// std::lower_bound over the whole list returns, whatever the cursor. The
// cursor is moved to the answer.
inline std::size_t lowerBoundFrom(std::span<const std::uint64_t> keys, std::uint64_t key, std::size_t& cursor) {
  const std::size_t n = keys.size();
  std::size_t lo = std::min(cursor, n), hi = lo;
  if (lo > 0 && keys[lo - 1] >= key) {
    lo = 0;  // behind the cursor
  } else {  // every key before lo is below `key`
    for (std::size_t stride = 1; hi < n && keys[hi] < key; stride *= 2) {
      lo = hi + 1;
      hi = std::min(n, lo + stride);
    }
  }
  cursor = static_cast<std::size_t>(std::lower_bound(keys.begin() + static_cast<std::ptrdiff_t>(lo),
                                                     keys.begin() + static_cast<std::ptrdiff_t>(hi), key) -
                                    keys.begin());
  return cursor;
}

}  // namespace cairn::detail
