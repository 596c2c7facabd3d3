// Large arrays on transparent huge pages. With the kernel's THP setting at "madvise" (Debian's default), anonymous
// memory gets 2 MiB pages only where the process asks; the voxelizer's reference arrays at 1024^3 (tens of MB each,
// written once front to back) otherwise spend a fifth of their time in 4 KiB page faults (docs/voxelize-speed.md).
// On the virtual machines we run on a 4 KiB page fault costs 12-16 us: 2.5 MB of fresh 4 KiB pages cost as much
// time as parsing them from an OBJ text.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

namespace vox {

// Asks for huge pages on the whole 2 MiB pages inside [data, data + bytes) (madvise MADV_HUGEPAGE), before the
// memory is first touched. A hint: nothing changes but speed, and a kernel without THP ignores it. Below 4 MiB it
// does nothing (a single huge page would be mostly empty).
void adviseHugePages(const void* data, size_t bytes);

// Allocations of at least this many bytes are whole 2 MiB-aligned huge pages (HugePageAllocator): one fault that
// zeroes 2 MiB costs less than the 64 faults of 256 KiB on 4 KiB pages, so the memory left over is worth it.
constexpr size_t kHugePageBytes = size_t{2} << 20;
constexpr size_t kHugeAllocationMin = size_t{256} << 10;

// `bytes` (at least kHugeAllocationMin) on their own 2 MiB-aligned mapping, rounded up to whole huge pages and
// advised as such; not zeroed (the kernel hands out zero pages). Throws std::bad_alloc. Freed by releaseHugePages
// with the same `bytes`.
void* mapHugePages(size_t bytes);
void releaseHugePages(void* data, size_t bytes);

// A std::allocator whose large blocks (kHugeAllocationMin and more) are whole huge pages: malloc places a large
// block at an address it chooses (and glibc's moving mmap threshold may put it in the heap), so madvise on it
// covers only the 2 MiB pages inside, leaving up to 4 MiB of it to 4 KiB faults. Smaller blocks come from operator
// new. Stateless: any two compare equal.
template <typename T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}  // NOLINT: converting, as std::allocator's

  T* allocate(size_t n) {
    if (n > size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    const size_t bytes = n * sizeof(T);
    if (bytes < kHugeAllocationMin) return std::allocator<T>().allocate(n);
    return static_cast<T*>(mapHugePages(bytes));
  }
  void deallocate(T* p, size_t n) noexcept {
    const size_t bytes = n * sizeof(T);
    if (bytes < kHugeAllocationMin)
      std::allocator<T>().deallocate(p, n);
    else
      releaseHugePages(p, bytes);
  }
  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

// A vector whose storage, once large, is whole huge pages.
template <typename T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

// n elements of a trivial type, not initialised (a sort's buffers, written whole before they are read), from
// HugePageAllocator.
template <typename T>
struct HugeArrayDeleter {
  size_t n = 0;
  void operator()(T* p) const noexcept { HugePageAllocator<T>().deallocate(p, n); }
};
template <typename T>
using HugeArray = std::unique_ptr<T[], HugeArrayDeleter<T>>;
template <typename T>
HugeArray<T> makeHugeArray(size_t n) {
  static_assert(std::is_trivial_v<T>);
  return HugeArray<T>(HugePageAllocator<T>().allocate(n), HugeArrayDeleter<T>{n});
}

// v.reserve(n), then adviseHugePages on the capacity not yet written (the part the kernel has not faulted in): for a
// std::vector whose block malloc places. A HugeVector needs only reserve(): its allocator maps whole huge pages.
template <typename T, typename A>
void reserveOnHugePages(std::vector<T, A>& v, size_t n) {
  v.reserve(n);
  adviseHugePages(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
}

}  // namespace vox
