// LSD radix sort of 64-bit keys on their low `bits` bits, 11 bits a pass: sorting the packed (cell, primitive)
// references is the voxelizer's largest cost after the overlap tests, and comparison sorts are several times slower.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace vox {

inline void radixSort(std::vector<uint64_t>& keys, int bits) {
  constexpr int kDigit = 11;
  constexpr size_t kBuckets = size_t(1) << kDigit;
  std::vector<uint64_t> buffer(keys.size());
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::array<size_t, kBuckets> count{};
    for (uint64_t k : keys) ++count[(k >> shift) & (kBuckets - 1)];
    size_t sum = 0;
    for (auto& c : count) {
      const size_t n = c;
      c = sum;
      sum += n;
    }
    for (uint64_t k : keys) buffer[count[(k >> shift) & (kBuckets - 1)]++] = k;
    keys.swap(buffer);
  }
}

}  // namespace vox
