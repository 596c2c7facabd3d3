// LSD radix sort of 64-bit keys on their low `bits` bits, 11 bits a pass: sorting the packed (cell, primitive)
// references is the voxelizer's largest cost after the overlap tests, and comparison sorts are several times slower.
// The keys come in parts (one per thread) and are sorted straight out of them: no copy into one array first, every
// digit counted in one pass over the input, the two work arrays uninitialised (no memset) and on huge pages (perf:
// page faults, memmove of the concatenation and memset of the buffer were a third of a 1024^3 voxelization).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "vox/core/huge_pages.h"

namespace vox {

// The keys of all `parts`, sorted ascending on their low `bits` bits (stable). Returns the array and its size.
inline std::pair<std::unique_ptr<uint64_t[]>, size_t> radixSortParts(std::span<const std::span<const uint64_t>> parts,
                                                                     int bits) {
  constexpr int kDigit = 11;
  constexpr size_t kBuckets = size_t(1) << kDigit;
  const int passes = std::max(1, (bits + kDigit - 1) / kDigit);
  size_t n = 0;
  for (const auto& p : parts) n += p.size();
  std::unique_ptr<uint64_t[]> a(new uint64_t[n]), b(new uint64_t[n]);  // default-initialised: not zeroed
  adviseHugePages(a.get(), n * sizeof(uint64_t));
  adviseHugePages(b.get(), n * sizeof(uint64_t));
  std::vector<std::array<size_t, kBuckets>> count(static_cast<size_t>(passes));
  for (auto& c : count) c.fill(0);
  for (const auto& p : parts)
    for (uint64_t k : p)
      for (int d = 0; d < passes; ++d) ++count[size_t(d)][(k >> (d * kDigit)) & (kBuckets - 1)];
  for (auto& c : count) {
    size_t sum = 0;
    for (auto& x : c) {
      const size_t m = x;
      x = sum;
      sum += m;
    }
  }
  // Pass 0 scatters from the parts into `a`; each further pass from the last output into the other array.
  for (const auto& p : parts)
    for (uint64_t k : p) a[count[0][k & (kBuckets - 1)]++] = k;
  for (int d = 1; d < passes; ++d) {
    auto& c = count[size_t(d)];
    const int shift = d * kDigit;
    for (size_t i = 0; i < n; ++i) {
      const uint64_t k = a[i];
      b[c[(k >> shift) & (kBuckets - 1)]++] = k;
    }
    a.swap(b);
  }
  return {std::move(a), n};
}

}  // namespace vox
