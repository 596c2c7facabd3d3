// The cells of one axis whose closed boxes meet [lo, hi], for any way of getting the boundaries b(0..n): from the
// formula (cellRange in grid.cpp) or from a precomputed table (the voxelizer's rows). The boundary formula is monotone
// in c, so a guess from `scale` (n / extent) and a few steps against the true boundaries give the exact answer.
// In core because the grid, the voxelizer and the packet tracer all need it.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace vox {

// first = smallest c in [0, n-1] with b(c+1) >= lo; last = largest c in [0, n-1] with b(c) <= hi; first > last when
// [lo, hi] misses [b(0), b(n)] (or is NaN).
template <typename BoundaryFn>
std::array<int64_t, 2> cellRangeOnAxis(int64_t n, double scale, const BoundaryFn& b, double lo, double hi) {
  const double b0 = b(0);
  if (!(hi >= b0) || !(lo <= b(n))) return {1, 0};
  // Clamped in double before the conversion, so far-away coordinates cannot overflow the integer. A scale that is
  // not finite (bounds of subnormal width) or a NaN product gives no usable guess: bisect instead.
  const bool usable = std::isfinite(scale);
  auto guess = [&](double x, auto&& below) {
    const double g = std::floor((x - b0) * scale);
    if (usable && g == g) return g < 0 ? int64_t(0) : (g > double(n - 1) ? n - 1 : int64_t(g));
    int64_t a = 0, z = n - 1;  // smallest c in [0, n-1] with !below(c), or n-1
    while (a < z) {
      const int64_t mid = a + (z - a) / 2;
      if (below(mid))
        a = mid + 1;
      else
        z = mid;
    }
    return a;
  };
  int64_t first = guess(lo, [&](int64_t c) { return b(c + 1) < lo; });
  while (first > 0 && b(first) >= lo) --first;
  while (first < n - 1 && b(first + 1) < lo) ++first;
  int64_t last = guess(hi, [&](int64_t c) { return b(c + 1) <= hi; });
  while (last < n - 1 && b(last + 1) <= hi) ++last;
  while (last > 0 && b(last) > hi) --last;
  return {first, last};
}

}  // namespace vox
