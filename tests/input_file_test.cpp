// Tests of the untrusted-input guards: folder confinement, regular files only, memory budget, quoting.
#include "vox/io/input_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "vox/core/cell_range.h"
#include "vox/core/error.h"

namespace vox {
namespace {

namespace fs = std::filesystem;

struct TempFolder {
  fs::path root = fs::temp_directory_path() / ("vox_input_" + std::to_string(::getpid()));
  TempFolder() {
    fs::remove_all(root);
    fs::create_directories(root / "scene" / "sub");
    for (const char* f : {"secret.bin", "scene/a.bin", "scene/sub/b.bin"}) std::ofstream(root / f) << "x";
  }
  ~TempFolder() { fs::remove_all(root); }
  std::string scene() const { return (root / "scene" / "s.gltf").string(); }
};

TEST(InputFile, ReferencesStayInsideTheReferrersFolder) {
  const TempFolder t;
  EXPECT_EQ(resolveInsideFolder(t.scene(), "a.bin"), (fs::canonical(t.root) / "scene" / "a.bin").string());
  EXPECT_NO_THROW(resolveInsideFolder(t.scene(), "sub/b.bin"));
  EXPECT_NO_THROW(resolveInsideFolder(t.scene(), "sub/../a.bin"));
  EXPECT_NO_THROW(resolveInsideFolder(t.scene(), "./missing.bin"));  // missing is the reader's error, not this one
  for (const char* bad : {"../secret.bin", "sub/../../secret.bin", "/etc/passwd", "..", "../scene2/x"})
    EXPECT_THROW(resolveInsideFolder(t.scene(), bad), InputError) << bad;
  // A sibling folder whose name starts with the folder's name is outside.
  fs::create_directories(t.root / "scene2");
  EXPECT_THROW(requireInsideFolder(t.scene(), (t.root / "scene2" / "x").string()), InputError);
  // A symbolic link inside that leads out is outside.
  fs::create_symlink(t.root / "secret.bin", t.root / "scene" / "link.bin");
  EXPECT_THROW(resolveInsideFolder(t.scene(), "link.bin"), InputError);
  fs::create_directory_symlink(t.root, t.root / "scene" / "up");
  EXPECT_THROW(resolveInsideFolder(t.scene(), "up/secret.bin"), InputError);
}

TEST(InputFile, OnlyRegularFilesAreRead) {
  const TempFolder t;
  EXPECT_EQ(readInputFile((t.root / "secret.bin").string(), "test file"), "x");
  EXPECT_THROW(readInputFile((t.root / "scene").string(), "test file"), InputError);
  EXPECT_THROW(readInputFile((t.root / "none").string(), "test file"), InputError);
  const fs::path fifo = t.root / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(readInputFile(fifo.string(), "test file"), InputError);  // refused, not a read that blocks
  EXPECT_THROW(readInputFile("/dev/zero", "test file"), InputError);    // a device never ends
}

TEST(InputFile, MemoryBudgetFromTheEnvironment) {
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

TEST(InputFile, QuotedInputIsOneShortLine) {
  EXPECT_EQ(quoteInput("abc"), "abc");
  EXPECT_EQ(quoteInput("a\nb\x1b[31m\x7f"), "a\\x0ab\\x1b[31m\\x7f");
  EXPECT_EQ(quoteInput("caf\xc3\xa9"), "caf\xc3\xa9");  // UTF-8 passes
  EXPECT_EQ(quoteInput(std::string(10'000'000, 'A'), 40), std::string(40, 'A') + "...");
}

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
