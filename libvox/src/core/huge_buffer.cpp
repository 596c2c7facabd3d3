#include "vox/core/huge_buffer.h"

#include <utility>

#include "vox/core/huge_pages.h"

namespace vox {

HugeBuffer::HugeBuffer(size_t size) : size_(size) {
  if (size == 0) return;
  if (size < kHugePageBytes) {
    data_ = new char[size];
    return;
  }
  data_ = static_cast<char*>(mapHugePages(size));
  mapped_ = size;
}

HugeBuffer::HugeBuffer(HugeBuffer&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      mapped_(std::exchange(other.mapped_, 0)) {}

HugeBuffer& HugeBuffer::operator=(HugeBuffer&& other) noexcept {
  if (this != &other) {
    release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapped_ = std::exchange(other.mapped_, 0);
  }
  return *this;
}

HugeBuffer::~HugeBuffer() { release(); }

void HugeBuffer::release() {
  if (mapped_ > 0)
    releaseHugePages(data_, mapped_);
  else
    delete[] data_;
  data_ = nullptr;
  size_ = mapped_ = 0;
}

}  // namespace vox
