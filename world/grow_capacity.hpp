// Room for n elements in a per-step list, its capacity at least doubled
// when it must grow: what a push_back does, for the lists a stage clears
// and then sizes whole with resize or assign. libstdc++ gives those
// exactly n (a resize from empty, or an assign past the capacity), so a
// scene whose contacts grow a little each step (a pile landing layer by
// layer) allocated its contact batches afresh at every layer. An
// allocation of that size is fresh memory from the kernel each time, and
// a page's first touch is a fault: 11 us each on the 2-CPU virtual machine
// the figures come from, up to 410 of them in a step where a layer of
// pile-1000 landed (4.9 to 7.1 ms for the last four layers' steps against
// 2 for the steps around them; docs/performance.md). Grown by doubling,
// a list reallocates a few times in a run. Only the capacity changes: the
// contents are what the resize or assign that follows makes.
#pragma once

#include <algorithm>
#include <cstddef>

namespace cairn::detail {

template <class Vector>
void reserveGrowing(Vector& v, std::size_t n) {
  if (n > v.capacity()) v.reserve(std::max(n, 2 * v.capacity()));
}

// v.resize(n) and v.assign(n, value), the capacity grown as above first.
template <class Vector>
void resizeGrowing(Vector& v, std::size_t n) {
  reserveGrowing(v, n);
  v.resize(n);
}
template <class Vector, class T>
void assignGrowing(Vector& v, std::size_t n, const T& value) {
  reserveGrowing(v, n);
  v.assign(n, value);
}

}  // namespace cairn::detail
