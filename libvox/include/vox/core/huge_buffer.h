// A large byte buffer on transparent huge pages, whole. On the virtual machines we run on, a 4 KiB page fault costs
// 12-16 us and even a read into pages already faulted in is ten times slower than into huge pages (TLB misses
// under nested paging): reading a 4.8 MB OBJ into a std::string took 9 ms for the copy from the page cache and 18
// ms for zeroing it first, against 1 ms and 0.5-4 ms on huge pages (docs/voxelize-speed.md, "Huge pages, whole").
// madvise alone (huge_pages.h) covers only the 2 MiB pages inside a malloc'd block, whose start the allocator
// chooses; this buffer maps its own memory 2 MiB-aligned, so every page of it is huge, and is not zeroed first.
#pragma once

#include <cstddef>
#include <string_view>

namespace vox {

class HugeBuffer {
 public:
  HugeBuffer() = default;
  // `size` bytes, uninitialised. Below 2 MiB an ordinary allocation (a huge page would be mostly empty). Throws
  // std::bad_alloc when the memory cannot be had.
  explicit HugeBuffer(size_t size);
  HugeBuffer(HugeBuffer&& other) noexcept;
  HugeBuffer& operator=(HugeBuffer&& other) noexcept;
  HugeBuffer(const HugeBuffer&) = delete;
  HugeBuffer& operator=(const HugeBuffer&) = delete;
  ~HugeBuffer();

  char* data() { return data_; }
  const char* data() const { return data_; }
  size_t size() const { return size_; }
  std::string_view view() const { return {data_, size_}; }
  // Shortens the buffer (a file that shrank while read); the memory stays mapped until destruction.
  void shrink(size_t size) { size_ = size < size_ ? size : size_; }

 private:
  void release();

  char* data_ = nullptr;
  size_t size_ = 0;
  size_t mapped_ = 0;  // the bytes asked of mapHugePages for data_, or 0 when data_ came from new[]
};

}  // namespace vox
