// The allocator of the solver's largest arrays (solver/huge_page_allocator.hpp):
// an array of 2 MiB or more starts on a 2 MiB boundary, so the kernel can
// back it with huge pages from its first byte; a smaller one keeps its
// type's alignment (a contact batch's 64 bytes, the kernels' aligned
// loads); a vector that grows across the threshold keeps its contents (the
// two paths free what they allocated: the sanitizer build checks that).
#include "solver/contact_batch.hpp"
#include "solver/huge_page_allocator.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace cairn {
namespace {

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

TEST(HugePageAllocator, LargeArraysStartOnAHugePageAndSmallOnesKeepTheirAlignment) {
  using Batches = std::vector<ContactBatch, HugePageAllocator<ContactBatch>>;
  const size_t per_page = kHugePage / sizeof(ContactBatch) + 1;  // just past 2 MiB
  Batches small(4), large(per_page);
  EXPECT_EQ(address(small.data()) % alignof(ContactBatch), 0u);
  EXPECT_EQ(address(large.data()) % kHugePage, 0u);
}

TEST(HugePageAllocator, AVectorGrowingPastTheThresholdKeepsItsContents) {
  std::vector<ContactBatch, HugePageAllocator<ContactBatch>> batches;
  const int n = static_cast<int>(3 * kHugePage / sizeof(ContactBatch));
  for (int i = 0; i < n; ++i) {
    batches.emplace_back();
    batches.back().body_a[0] = i;
  }
  for (int i = 0; i < n; ++i) ASSERT_EQ(batches[static_cast<size_t>(i)].body_a[0], i);
  EXPECT_EQ(address(batches.data()) % kHugePage, 0u);
  batches.resize(2);
  batches.shrink_to_fit();
  EXPECT_EQ(batches[1].body_a[0], 1);
}

}  // namespace
}  // namespace cairn
