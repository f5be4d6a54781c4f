// The per-step lists' growth (world/grow_capacity.hpp): a list cleared and
// sized whole every step, a little longer each time (a pile's contacts as
// it lands), is allocated a logarithmic number of times, and holds exactly
// what a plain resize or assign makes.
#include "world/grow_capacity.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <memory>
#include <vector>

namespace cairn::detail {
namespace {

int g_allocations = 0;

template <class T>
struct CountingAllocator {
  using value_type = T;
  CountingAllocator() = default;
  template <class U>
  CountingAllocator(const CountingAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    ++g_allocations;
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) noexcept { std::allocator<T>().deallocate(p, n); }
  template <class U>
  bool operator==(const CountingAllocator<U>&) const noexcept {
    return true;
  }
};

TEST(GrowCapacity, AListSizedWholeEachStepAndGrowingByOneIsAllocatedLogarithmicallyOften) {
  g_allocations = 0;
  std::vector<int, CountingAllocator<int>> assigned, resized;
  constexpr int kSteps = 2000;
  for (int n = 1; n <= kSteps; ++n) {
    const auto size = static_cast<std::size_t>(n);
    assigned.clear();
    assignGrowing(assigned, size, -1);
    resized.clear();
    resizeGrowing(resized, size);
  }
  // Doubling from one element: capacities 1, 2, 4, ... 2048, twelve
  // allocations a list. Reserving exactly n would make 2,000 each.
  EXPECT_LE(g_allocations, 2 * 12);
  ASSERT_EQ(assigned.size(), std::size_t(kSteps));
  ASSERT_EQ(resized.size(), std::size_t(kSteps));
  for (std::size_t i = 0; i < assigned.size(); ++i) {
    ASSERT_EQ(assigned[i], -1);
    ASSERT_EQ(resized[i], 0);  // value-initialised, as a resize without the reservation
  }
}

TEST(GrowCapacity, AListWithRoomEnoughKeepsItsAllocation) {
  std::vector<int> v(100, 7);
  const int* data = v.data();
  v.clear();
  assignGrowing(v, 50, 3);
  EXPECT_EQ(v.data(), data);
  EXPECT_EQ(v.capacity(), 100u);
}

}  // namespace
}  // namespace cairn::detail
