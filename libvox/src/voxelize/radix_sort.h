// Radix sort of 64-bit keys on their low `bits` bits: sorting the packed (cell, primitive) references is the
// voxelizer's largest cost after the overlap tests, and comparison sorts are several times slower. The keys come in
// parts (one per thread) and are sorted straight out of them: no copy into one array first, the two work arrays
// uninitialised (no memset) and on huge pages (perf: page faults, memmove of the concatenation and memset of the
// buffer were a third of a 1024^3 voxelization).
//
// Large inputs are sorted in two steps that both use every thread: one pass on the top digit scatters the keys into
// buckets (each block of the input counted, then scattered, in parallel), then each bucket is sorted on the
// remaining bits by LSD passes inside the cache (the bunny's 5.1 M references at 1024^3 make buckets of about
// 10 thousand keys). Small inputs take the LSD passes over the whole array on one thread.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "vox/core/huge_pages.h"

namespace vox {

namespace radix_detail {

constexpr int kDigit = 11;
constexpr size_t kBuckets = size_t(1) << kDigit;
using Counts = std::array<size_t, kBuckets>;

// Turns counts into start offsets, in place.
inline void exclusiveSum(Counts& c) {
  size_t sum = 0;
  for (auto& x : c) {
    const size_t m = x;
    x = sum;
    sum += m;
  }
}

// LSD passes over a[0, n) on bits [0, bits), digit by digit, b as scratch; the result ends in a.
inline void lsdSort(uint64_t* a, uint64_t* b, size_t n, int bits) {
  const int passes = (bits + kDigit - 1) / kDigit;
  std::vector<Counts> count(static_cast<size_t>(passes));
  for (auto& c : count) c.fill(0);
  for (size_t i = 0; i < n; ++i)
    for (int d = 0; d < passes; ++d) ++count[size_t(d)][(a[i] >> (d * kDigit)) & (kBuckets - 1)];
  for (auto& c : count) exclusiveSum(c);
  for (int d = 0; d < passes; ++d) {
    auto& c = count[size_t(d)];
    const int shift = d * kDigit;
    for (size_t i = 0; i < n; ++i) b[c[(a[i] >> shift) & (kBuckets - 1)]++] = a[i];
    std::swap(a, b);
  }
  if (passes % 2 == 1) std::memcpy(b, a, n * sizeof(uint64_t));  // after an odd number of swaps `a` is the scratch
}

struct Block {
  const uint64_t* keys;
  size_t size;
};

}  // namespace radix_detail

// Inputs below this many keys are sorted on one thread.
inline constexpr size_t kParallelSortFrom = size_t(1) << 16;

// The keys of all `parts`, sorted ascending on their low `bits` bits (stable). Returns the array and its size.
// `check` (may be empty) is called between tasks of the parallel sort, from any thread; it throws to cancel (a sort
// of 20 M keys takes half a second, too long for Ctrl-C to wait).
inline std::pair<HugeArray<uint64_t>, size_t> radixSortParts(std::span<const std::span<const uint64_t>> parts, int bits,
                                                             size_t parallelFrom = kParallelSortFrom,
                                                             const std::function<void()>& check = {}) {
  using namespace radix_detail;
  const auto poll = [&] {
    if (check) check();
  };
  size_t n = 0;
  for (const auto& p : parts) n += p.size();
  // Not zeroed, on whole huge pages: malloc'd and advised, 2 x 41 MB for the bunny at 1024^3 still took a
  // thousand 4 KiB faults at their unaligned ends.
  HugeArray<uint64_t> a = makeHugeArray<uint64_t>(n), b = makeHugeArray<uint64_t>(n);
  if (n < parallelFrom) {  // one thread: the parts side by side, then LSD passes over all of them
    size_t at = 0;
    for (const auto& p : parts) {
      if (!p.empty()) std::memcpy(a.get() + at, p.data(), p.size() * sizeof(uint64_t));
      at += p.size();
    }
    lsdSort(a.get(), b.get(), n, bits);
    return {std::move(a), n};
  }
  const int top = std::min(bits, kDigit), shift = bits - top;
  const uint64_t topMask = (uint64_t(1) << top) - 1;
  // The input cut into blocks, each counted and then scattered on the top digit by one task.
  const size_t blockSize = size_t(1) << 16;
  std::vector<Block> blocks;
  for (const auto& p : parts)
    for (size_t i = 0; i < p.size(); i += blockSize)
      blocks.push_back({p.data() + i, std::min(blockSize, p.size() - i)});
  std::vector<Counts> count(blocks.size());
  tbb::parallel_for(size_t(0), blocks.size(), [&](size_t k) {
    poll();
    count[k].fill(0);
    for (size_t i = 0; i < blocks[k].size; ++i) ++count[k][(blocks[k].keys[i] >> shift) & topMask];
  });
  // Bucket starts, and each block's place inside each bucket (blocks in input order: the scatter is stable).
  Counts bucketStart{};
  for (size_t d = 0; d < kBuckets; ++d) {
    size_t sum = 0;
    for (auto& c : count) {
      const size_t m = c[d];
      c[d] = sum;
      sum += m;
    }
    bucketStart[d] = sum;
  }
  exclusiveSum(bucketStart);
  poll();
  tbb::parallel_for(size_t(0), blocks.size(), [&](size_t k) {
    poll();
    Counts& c = count[k];
    for (size_t d = 0; d < kBuckets; ++d) c[d] += bucketStart[d];
    for (size_t i = 0; i < blocks[k].size; ++i) {
      const uint64_t key = blocks[k].keys[i];
      a[c[(key >> shift) & topMask]++] = key;
    }
  });
  if (shift > 0) {
    tbb::parallel_for(size_t(0), kBuckets, [&](size_t d) {
      if (d % 64 == 0) poll();
      const size_t begin = bucketStart[d], end = d + 1 < kBuckets ? bucketStart[d + 1] : n;
      // A bucket smaller than a digit's counts sorts faster by comparison (stable, on the low bits only).
      if (end - begin < kBuckets / 4) {
        const uint64_t low = shift >= 64 ? ~uint64_t(0) : (uint64_t(1) << shift) - 1;
        std::stable_sort(a.get() + begin, a.get() + end,
                         [low](uint64_t x, uint64_t y) { return (x & low) < (y & low); });
      } else {
        lsdSort(a.get() + begin, b.get() + begin, end - begin, shift);
      }
    });
  }
  return {std::move(a), n};
}

}  // namespace vox
