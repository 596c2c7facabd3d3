// The huge-page requests change speed only: arrays keep their contents through every reservation and growth step,
// a mesh large enough to cross many growth steps reads back bit for bit, and HugeBuffer holds every byte of its size
// on whole 2 MiB pages (issue 26).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "import/obj_reader.h"
#include "vox/core/error.h"
#include "vox/core/huge_buffer.h"
#include "vox/core/huge_pages.h"
#include "vox/io/input_file.h"
#include "test_util.h"

namespace vox {
namespace {

TEST(HugePages, ReserveKeepsContentsAndGrowsCapacity) {
  std::vector<uint64_t> v;
  for (uint64_t i = 0; i < 1000; ++i) v.push_back(i * 2654435761u);
  reserveOnHugePages(v, size_t{3} << 20);  // 24 MiB: several whole huge pages
  ASSERT_GE(v.capacity(), size_t{3} << 20);
  ASSERT_EQ(v.size(), 1000u);
  for (uint64_t i = 0; i < 1000; ++i) ASSERT_EQ(v[i], i * 2654435761u);
  reserveOnHugePages(v, 10);  // never shrinks
  EXPECT_GE(v.capacity(), size_t{3} << 20);
}

TEST(HugePages, AdviceOnSmallOrNullRangesIsHarmless) {
  adviseHugePages(nullptr, size_t{1} << 30);
  const char small[16] = {};
  adviseHugePages(small, sizeof small);
  SUCCEED();
}

// 300,000 vertices and faces (about 20 growth steps of each array) read back exactly as written.
TEST(HugePages, LargeObjReadsBackBitForBit) {
  std::mt19937_64 random(26);
  std::uniform_real_distribution<double> coordinate(-1e3, 1e3);
  constexpr size_t kVertices = 300000;
  std::vector<double> written(3 * kVertices);
  std::string text;
  text.reserve(kVertices * 90);
  char line[128];
  for (size_t i = 0; i < kVertices; ++i) {
    for (int k = 0; k < 3; ++k) written[3 * i + size_t(k)] = coordinate(random);
    std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", written[3 * i], written[3 * i + 1], written[3 * i + 2]);
    text += line;
  }
  for (size_t i = 0; i + 2 < kVertices; ++i) {
    std::snprintf(line, sizeof line, "f %zu %zu -1\n", i + 1, i + 2);
    text += line;
  }
  const ObjData obj = parseObj(text, "large.obj");
  ASSERT_EQ(obj.vertices.size(), kVertices);
  ASSERT_EQ(obj.triangles.size(), kVertices - 2);
  ASSERT_EQ(obj.triangleMaterial.size(), kVertices - 2);
  for (size_t i = 0; i < kVertices; ++i) {
    const double got[3] = {obj.vertices[i].x, obj.vertices[i].y, obj.vertices[i].z};
    ASSERT_EQ(std::memcmp(got, &written[3 * i], sizeof got), 0) << "vertex " << i;
  }
  for (size_t i = 0; i + 2 < kVertices; ++i) {
    ASSERT_EQ(obj.triangles[i][0], i);
    ASSERT_EQ(obj.triangles[i][1], i + 1);
    ASSERT_EQ(obj.triangles[i][2], kVertices - 1);  // -1: the last vertex read, all are read before the faces
  }
}

// HugeVector keeps every value across the threshold between operator new and whole huge pages, through growth one
// element at a time, copies, moves and shrinking; its large blocks start on a 2 MiB boundary.
TEST(HugePages, HugeVectorHoldsItsValuesOnBothSidesOfTheThreshold) {
  const size_t atThreshold = kHugeAllocationMin / sizeof(uint64_t);
  for (size_t n : {size_t{0}, size_t{1}, atThreshold - 1, atThreshold, atThreshold + 1, 3 * kHugePageBytes / 8 + 5}) {
    HugeVector<uint64_t> grown;
    for (uint64_t i = 0; i < n; ++i) grown.push_back(i * 0x9E3779B97F4A7C15u);
    HugeVector<uint64_t> sized(n);
    for (uint64_t i = 0; i < n; ++i) sized[i] = i * 0x9E3779B97F4A7C15u;
    ASSERT_EQ(grown, sized) << n;
    if (n * sizeof(uint64_t) >= kHugeAllocationMin) {
      EXPECT_EQ(reinterpret_cast<uintptr_t>(sized.data()) % kHugePageBytes, 0u) << n;
    }
    const HugeVector<uint64_t> copy = grown;
    HugeVector<uint64_t> moved = std::move(grown);
    ASSERT_EQ(copy, moved) << n;
    moved.resize(n / 3);
    moved.shrink_to_fit();  // from a huge block to a small one, or to none
    for (size_t i = 0; i < moved.size(); ++i) ASSERT_EQ(moved[i], copy[i]) << n;
  }
}

TEST(HugeBuffer, HoldsEveryByteOfItsSizeOnWholeHugePages) {
  constexpr size_t kHuge = size_t{2} << 20;
  for (size_t size : {size_t{0}, size_t{1}, kHuge - 1, kHuge, kHuge + 1, 5 * kHuge + 12345}) {
    HugeBuffer b(size);
    ASSERT_EQ(b.size(), size);
    ASSERT_EQ(b.view().size(), size);
    if (size == 0) continue;
    if (size >= kHuge) {
      EXPECT_EQ(reinterpret_cast<uintptr_t>(b.data()) % kHuge, 0u) << size;
    }
    for (size_t i = 0; i < size; ++i) b.data()[i] = char(i * 7);  // every byte writable (ASan checks the range)
    HugeBuffer moved(std::move(b));
    EXPECT_EQ(b.size(), 0u);
    EXPECT_EQ(b.data(), nullptr);
    ASSERT_EQ(moved.size(), size);
    EXPECT_EQ(moved.data()[size - 1], char((size - 1) * 7));
    HugeBuffer assigned(kHuge + 3);
    assigned = std::move(moved);  // the old mapping released, the new one kept
    EXPECT_EQ(assigned.data()[size / 2], char((size / 2) * 7));
    assigned.shrink(size / 2);
    EXPECT_EQ(assigned.size(), size / 2);
    assigned.shrink(size);  // never grows
    EXPECT_EQ(assigned.size(), size / 2);
  }
}

TEST(HugeBuffer, ReadInputBytesReadsWhatReadInputFileReads) {
  testing::ScratchDir dir("hugebuf");
  std::mt19937 random(26);
  for (size_t size : {size_t{0}, size_t{100}, (size_t{2} << 20) + 77, size_t{9} << 20}) {
    std::string bytes(size, '\0');
    for (char& c : bytes) c = char(random());
    const std::string path = dir.file("f" + std::to_string(size));
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(bytes.data(), 1, bytes.size(), f), bytes.size());
    std::fclose(f);
    EXPECT_EQ(readInputBytes(path, "test file").view(), bytes);
    EXPECT_EQ(readInputFile(path, "test file"), bytes);
  }
  EXPECT_THROW(readInputBytes(dir.file("none"), "test file"), InputError);
  EXPECT_THROW(readInputBytes("/dev/zero", "test file"), InputError);
}

}  // namespace
}  // namespace vox
