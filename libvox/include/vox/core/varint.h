// LEB128 varints, the one encoding of small unsigned integers libvox uses (grid file version 3's cell table, the
// grid-set fill's packed keys and runs): seven bits a byte, low bits first, the top bit set on every byte but the
// last. Written in their shortest form, so a value has exactly one encoding.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace vox {

// The bytes v takes (1 to 10).
inline size_t varintSize(uint64_t v) { return (size_t(std::bit_width(v | 1)) + 6) / 7; }

// Writes v at p (room for varintSize(v) bytes); returns the byte after it.
inline uint8_t* putVarint(uint8_t* p, uint64_t v) {
  for (; v >= 0x80; v >>= 7) *p++ = uint8_t(v) | 0x80;
  *p++ = uint8_t(v);
  return p;
}

inline void appendVarint(std::vector<uint8_t>& bytes, uint64_t v) {
  uint8_t buffer[10];
  bytes.insert(bytes.end(), buffer, putVarint(buffer, v));
}

enum class VarintStatus { Ok, Truncated, Malformed };

// Reads the varint at p into v and moves p past it. Truncated: the bytes end inside it; Malformed: not in its
// shortest form (a last byte of 0) or past 64 bits. Never reads at or past `end`.
inline VarintStatus getVarint(const uint8_t*& p, const uint8_t* end, uint64_t& v) {
  if (p < end && *p < 0x80) {  // most values: one byte
    v = *p++;
    return VarintStatus::Ok;
  }
  v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    if (p == end) return VarintStatus::Truncated;
    const uint8_t b = *p++;
    if ((shift == 63 && b > 1) || (shift > 0 && b == 0)) return VarintStatus::Malformed;
    v |= uint64_t(b & 0x7f) << shift;
    if (b < 0x80) return VarintStatus::Ok;
  }
  return VarintStatus::Malformed;
}

}  // namespace vox
