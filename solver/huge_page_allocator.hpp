// An allocator for the solver's largest arrays that asks Linux to back
// them with 2 MiB pages (transparent huge pages, madvise), and leaves the
// elements a resize adds uninitialised (below).
//
// A large island's contact batches are tens of megabytes (13 KB a batch:
// 24 MB for the 5,050-box pyramid), walked once or more per sweep. With
// 4 KiB pages a batch spans four pages and the walk leaves the reach of
// the core's second-level TLB (1,536 to 2,048 entries on recent Xeons, 6
// to 8 MB), so most batches cost page walks; with 2 MiB pages the whole
// array takes a dozen entries. Debian's default is THP on madvise only,
// so the memory must ask for it. Measured on the 5,050-box pyramid: its
// solve 1.15 times faster on one thread (docs/performance.md). Below
// 2 MiB, or off Linux, this is the plain aligned allocation.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace cairn {

inline constexpr std::size_t kHugePage = std::size_t(2) << 20;

template <class T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  static bool huge(std::size_t n) { return n * sizeof(T) >= kHugePage; }

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    if (!huge(n)) return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(alignof(T))));
    const std::size_t bytes = (n * sizeof(T) + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, bytes);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, bytes, MADV_HUGEPAGE);  // advice only: without THP the pages stay small
#endif
    return static_cast<T*>(p);
  }

  // Elements made without arguments are default-initialised, not zeroed:
  // a vector's resize leaves the new batches' memory as it is, since the
  // fill kernel writes every field the sweeps read before they read it
  // (contact_kernel_impl.hpp). Zeroing them was a memset of the whole
  // array every step: 24 MB, 4% of the 5,050-box pyramid's step.
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(static_cast<Args&&>(args)...);
  }

  void deallocate(T* p, std::size_t n) noexcept {
    if (!huge(n)) ::operator delete(p, std::align_val_t(alignof(T)));
    else std::free(p);
  }

  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

}  // namespace cairn
