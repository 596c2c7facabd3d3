// Tests of cellRangeOnAxis (cell_range.h) where the guess from the scale cannot be used.
#include "vox/core/cell_range.h"

#include <gtest/gtest.h>

#include <cmath>

namespace vox {
namespace {

// Bounds of subnormal width make the guess scale infinite (n / 1e-323): the range must come from bisection,
// never from converting inf or NaN to an integer (the old loop then started at INT64_MIN and never ended).
TEST(CellRange, InfiniteScaleBisects) {
  const double lo = 0, hi = 5e-324 * 4;  // four denormal steps
  const int64_t n = 4;
  auto b = [&](int64_t c) { return lo + (hi - lo) * double(c) / double(n); };
  const double scale = double(n) / (hi - lo);
  ASSERT_TRUE(std::isinf(scale));
  for (int64_t first = 0; first < n; ++first)
    for (int64_t last = first; last < n; ++last) {
      const auto r = cellRangeOnAxis(n, scale, b, b(first) + (first ? 5e-324 : 0), b(last));
      EXPECT_EQ(r[0], first);
      EXPECT_EQ(r[1], last);
    }
  const auto all = cellRangeOnAxis(
      1 << 21, HUGE_VAL, [](int64_t c) { return c * 5e-324; }, 0, 5e-324 * 7);
  EXPECT_EQ(all[0], 0);
  EXPECT_EQ(all[1], 7);
  const auto nan = cellRangeOnAxis(n, NAN, b, 0, hi);
  EXPECT_EQ(nan[0], 0);
  EXPECT_EQ(nan[1], n - 1);
}

}  // namespace
}  // namespace vox
