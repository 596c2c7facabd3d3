// Tests of the memory budget (memory_budget.cpp): the environment's limit and the messages over it.
#include "vox/core/memory_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "vox/core/error.h"

namespace vox {
namespace {

TEST(MemoryBudget, FromTheEnvironment) {
  ::setenv("VOX_MEMORY_LIMIT_MB", "3", 1);
  EXPECT_EQ(memoryBudgetBytes(), 3u << 20);
  EXPECT_NO_THROW(checkMemory(3 << 20, "f", "x"));
  try {
    checkMemory(double(5 << 20), "f.obj", "reading it");
    FAIL();
  } catch (const LimitError& e) {
    EXPECT_STREQ(e.what(), "f.obj: reading it needs about 5 MiB, more than the 3 MiB allowed");
  }
  EXPECT_THROW(checkMemory(HUGE_VAL, "f", "x"), LimitError);
  EXPECT_THROW(checkMemory(NAN, "f", "x"), LimitError);
  ::setenv("VOX_MEMORY_LIMIT_MB", "garbage", 1);
  EXPECT_GT(memoryBudgetBytes(), 3u << 20);  // ignored: physical memory decides
  ::unsetenv("VOX_MEMORY_LIMIT_MB");
}

}  // namespace
}  // namespace vox
