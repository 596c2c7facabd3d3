// Checked arithmetic for size estimates: a count or byte estimate that input decides (cells, runs, voxels, nodes)
// is computed so that it cannot wrap. The saturating forms stay at UINT64_MAX once a step overflows, so an estimate
// that overflows is larger than every budget and is refused like any other too-large request, never a small wrapped
// number that passes the check and then fails inside an allocation (std::length_error "vector::reserve").
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>

namespace vox {

// a + b, or UINT64_MAX when the sum does not fit in 64 bits.
constexpr uint64_t saturatingAdd(uint64_t a, uint64_t b) {
  uint64_t r = 0;
  return __builtin_add_overflow(a, b, &r) ? UINT64_MAX : r;
}
// a * b, or UINT64_MAX when the product does not fit in 64 bits.
constexpr uint64_t saturatingMul(uint64_t a, uint64_t b) {
  uint64_t r = 0;
  return __builtin_mul_overflow(a, b, &r) ? UINT64_MAX : r;
}
// The saturating sum and product of several terms.
constexpr uint64_t saturatingSum(std::initializer_list<uint64_t> terms) {
  uint64_t s = 0;
  for (uint64_t t : terms) s = saturatingAdd(s, t);
  return s;
}
constexpr uint64_t saturatingProduct(std::initializer_list<uint64_t> factors) {
  uint64_t p = 1;
  for (uint64_t f : factors) p = saturatingMul(p, f);
  return p;
}

// A count for a message: the number in decimal, with its power of two when it is one from 2^32 up ("9223372036854775808
// (2^63)"), and "2^64 - 1 or more" for a saturated estimate (UINT64_MAX).
inline std::string describeCount(uint64_t n) {
  if (n == UINT64_MAX) return "2^64 - 1 or more";
  std::string s = std::to_string(n);
  if (n >= (uint64_t(1) << 32) && (n & (n - 1)) == 0) s += " (2^" + std::to_string(__builtin_ctzll(n)) + ")";
  return s;
}

}  // namespace vox
