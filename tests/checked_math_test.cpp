// Tests of the checked arithmetic that size estimates use (vox/core/checked_math.h): exact below 2^64, saturated at
// UINT64_MAX from the first step that overflows, never wrapped.
#include "vox/core/checked_math.h"

#include <gtest/gtest.h>

namespace vox {
namespace {

TEST(CheckedMath, SumsAndProductsSaturateInsteadOfWrapping) {
  EXPECT_EQ(saturatingAdd(2, 3), 5u);
  EXPECT_EQ(saturatingAdd(UINT64_MAX - 1, 1), UINT64_MAX);
  EXPECT_EQ(saturatingAdd(UINT64_MAX - 1, 2), UINT64_MAX);
  EXPECT_EQ(saturatingMul(uint64_t(1) << 32, (uint64_t(1) << 32) - 1), UINT64_MAX - ((uint64_t(1) << 32) - 1));
  EXPECT_EQ(saturatingMul(uint64_t(1) << 32, uint64_t(1) << 32), UINT64_MAX);
  // The estimate of issue 23: 2^63 solid cells at 12 bytes wrapped to 0 and passed the budget.
  EXPECT_EQ((uint64_t(1) << 63) * 12, 0u);
  EXPECT_EQ(saturatingMul(uint64_t(1) << 63, 12), UINT64_MAX);
  EXPECT_EQ(saturatingMul(0, UINT64_MAX), 0u);
  EXPECT_EQ(saturatingSum({1, 2, UINT64_MAX, 0}), UINT64_MAX);
  EXPECT_EQ(saturatingSum({}), 0u);
  EXPECT_EQ(saturatingProduct({1u << 21, 1u << 21, 1u << 21}), uint64_t(1) << 63);
  EXPECT_EQ(saturatingProduct({1u << 21, 1u << 21, 1u << 21, 2}), UINT64_MAX);
  // Once saturated, it stays there: a later factor of 0 is the only way down, as in exact arithmetic.
  EXPECT_EQ(saturatingAdd(saturatingMul(UINT64_MAX, 2), 1), UINT64_MAX);
  static_assert(saturatingMul(3, 5) == 15);
}

TEST(CheckedMath, CountsForMessages) {
  EXPECT_EQ(describeCount(0), "0");
  EXPECT_EQ(describeCount(4096), "4096");  // powers of two below 2^32 stay plain
  EXPECT_EQ(describeCount(uint64_t(1) << 63), "9223372036854775808 (2^63)");
  EXPECT_EQ(describeCount((uint64_t(1) << 42) + 1), "4398046511105");
  EXPECT_EQ(describeCount(UINT64_MAX), "2^64 - 1 or more");
}

}  // namespace
}  // namespace vox
