// Large arrays on transparent huge pages. With the kernel's THP setting at "madvise" (Debian's default), anonymous
// memory gets 2 MiB pages only where the process asks; the voxelizer's reference arrays at 1024^3 (tens of MB each,
// written once front to back) otherwise spend a fifth of their time in 4 KiB page faults (docs/voxelize-speed.md).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace vox {

// Asks for huge pages on the whole 2 MiB pages inside [data, data + bytes) (madvise MADV_HUGEPAGE), before the
// memory is first touched. A hint: nothing changes but speed, and a kernel without THP ignores it. Below 4 MiB it
// does nothing (a single huge page would be mostly empty).
void adviseHugePages(const void* data, size_t bytes);

// v.reserve(n), then adviseHugePages on the capacity not yet written (the part the kernel has not faulted in).
template <typename T>
void reserveOnHugePages(std::vector<T>& v, size_t n) {
  v.reserve(n);
  adviseHugePages(v.data() + v.size(), (v.capacity() - v.size()) * sizeof(T));
}

// Before a push_back onto an array that may grow large: when it is full, doubles its capacity on huge pages, so
// that a reader growing its arrays one element at a time (an OBJ's vertices and faces) does not fault them in
// 4 KiB at a time.
template <typename T>
void growOnHugePages(std::vector<T>& v) {
  if (v.size() == v.capacity()) reserveOnHugePages(v, std::max<size_t>(v.capacity() * 2, 1024));
}

}  // namespace vox
