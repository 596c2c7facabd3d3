#include "vox/core/huge_pages.h"

#include <sys/mman.h>

#include <cstdint>

namespace vox {

void adviseHugePages(const void* data, size_t bytes) {
  constexpr uintptr_t kHuge = kHugePageBytes;
  if (data == nullptr || bytes < 2 * kHuge) return;
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  const uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end <= begin) return;
#ifdef MADV_HUGEPAGE
  // The result is ignored on purpose: EINVAL on a kernel built without THP changes nothing but speed.
  (void)::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
}

namespace {

size_t wholeHugePages(size_t bytes) { return (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1); }

}  // namespace

void* mapHugePages(size_t bytes) {
  if (bytes > SIZE_MAX - 2 * kHugePageBytes) throw std::bad_alloc();
  // Map one huge page more than needed, then unmap the unaligned head and tail, leaving whole 2 MiB pages.
  const size_t rounded = wholeHugePages(bytes);
  void* raw = ::mmap(nullptr, rounded + kHugePageBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t begin = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = (begin + kHugePageBytes - 1) & ~uintptr_t(kHugePageBytes - 1);
  if (aligned > begin) ::munmap(raw, aligned - begin);
  const uintptr_t tail = aligned + rounded;
  const uintptr_t end = begin + rounded + kHugePageBytes;
  if (end > tail) ::munmap(reinterpret_cast<void*>(tail), end - tail);
#ifdef MADV_HUGEPAGE
  // The result is ignored on purpose: EINVAL on a kernel built without THP changes nothing but speed.
  (void)::madvise(reinterpret_cast<void*>(aligned), rounded, MADV_HUGEPAGE);
#endif
  return reinterpret_cast<void*>(aligned);
}

void releaseHugePages(void* data, size_t bytes) {
  if (data != nullptr) ::munmap(data, wholeHugePages(bytes));
}

}  // namespace vox
