// The Distances section of grid files (io/grid_section_distances.cpp): version 5's runs of keys give back every band
// bit for bit, version 4 files (the flat keys the previous build wrote, from a checked-in file it made and from this
// test's own encoder of that layout) still read as written, every hostile body is refused in one line before any
// allocation the file cannot back, and a long band asks the reader's progress and can be cancelled.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "grid_file_util.h"
#include "io/byte_codec.h"
#include "io/grid_sections.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/core/varint.h"
#include "vox/io/grid_file.h"

namespace vox {
namespace {

using testing::resealed;

constexpr uint32_t kDistancesTag = 5;

uint32_t versionOf(const std::string& file) {
  uint32_t version = 0;
  std::memcpy(&version, file.data() + 8, 4);
  return version;
}

std::string tagged(const std::string& body) {
  std::string out(12, '\0');
  const uint64_t size = body.size();
  std::memcpy(&out[0], &kDistancesTag, 4);
  std::memcpy(&out[4], &size, 8);
  return out + body;
}

// The Distances section (tag, size, body) as this build writes it.
std::string currentSection(const Scene& scene, const Grid& grid) {
  ByteWriter w;
  std::string memo;
  putDistancesSection(w, scene, grid, memo);
  return tagged(w.bytes());
}

// Version 4's body, as the build before version 5 wrote it: half-width, u64 B, B u64 keys, B f64 distances.
std::string version4Body(const Grid& grid) {
  ByteWriter w;
  w.put(grid.sdfHalfWidth);
  w.putArray(grid.sdfKeys);
  w.putBytes({reinterpret_cast<const char*>(grid.sdfValues.data()), grid.sdfValues.size() * sizeof(double)});
  return w.bytes();
}

// `file` (this build's encoding of scene and grid) with its Distances section's body replaced by `body` and the
// header's version by `version`, resealed.
std::string withBody(const std::string& file, const Scene& scene, const Grid& grid, const std::string& body,
                     uint32_t version = kGridFileVersion) {
  const std::string section = currentSection(scene, grid);
  const size_t fractions = grid.fractions.empty() ? 0 : 12 + 8 + 8 * grid.fractions.size();  // the section after
  const size_t at = file.size() - fractions - section.size();
  EXPECT_EQ(file.compare(at, section.size(), section), 0) << "the Distances section is not where it should be";
  std::string out = file.substr(0, at) + tagged(body) + file.substr(at + section.size());
  std::memcpy(&out[8], &version, 4);
  return resealed(out);
}

// What the build before version 5 wrote for scene and grid.
std::string asVersion4(const Scene& scene, const Grid& grid) {
  return withBody(encodeGridFile(scene, grid), scene, grid, version4Body(grid), 4);
}

void expectSameBand(const Grid& a, const Grid& b) {
  EXPECT_EQ(a.sdfHalfWidth, b.sdfHalfWidth);
  EXPECT_EQ(a.sdfKeys, b.sdfKeys);
  ASSERT_EQ(a.sdfValues.size(), b.sdfValues.size());
  // Bit for bit: -0.0, subnormals and the last ulp all survive.
  EXPECT_EQ(std::memcmp(a.sdfValues.data(), b.sdfValues.data(), a.sdfValues.size() * sizeof(double)), 0);
}

// A band of random keys in runs of random lengths (singletons to whole rows, the grid's first and last cells
// included when `ends`), with random distances: any finite double, -0.0 and subnormals among them.
Grid randomBand(uint32_t seed, std::array<uint32_t, 3> dims, bool ends) {
  std::mt19937_64 rng(seed);
  Grid grid;
  grid.dims = dims;
  grid.bounds = {{0, 0, 0}, {1, 1, 1}};
  grid.sdfHalfWidth = 1 + double(rng() % 6300) / 100;
  const uint64_t cells = grid.cellCount();
  for (uint64_t key = ends ? 0 : rng() % std::min<uint64_t>(5, cells); key < cells;) {
    const uint64_t run = rng() % 4 == 0 ? 1 : 1 + rng() % (2 * dims[0]);
    for (uint64_t k = key; k < std::min(cells, key + run); ++k) grid.sdfKeys.push_back(k);
    key += run + 1 + rng() % 9;
  }
  if (ends && grid.sdfKeys.back() != cells - 1) grid.sdfKeys.push_back(cells - 1);
  for (size_t i = 0; i < grid.sdfKeys.size(); ++i) {
    double v = std::ldexp(double(int64_t(rng() >> 11)) - double(uint64_t(1) << 52), int(rng() % 80) - 60);
    if (i % 97 == 3) v = -0.0;
    if (i % 89 == 5) v = std::numeric_limits<double>::denorm_min() * double(1 + rng() % 1000);
    grid.sdfValues.push_back(v);
  }
  return grid;
}

TEST(GridSectionDistances, RandomBandsRoundTripBitForBitInVersion5AndRereadAsVersion4) {
  const Scene box = testing::boxScene(0.2, 0.8);
  uint32_t seed = 1;
  for (const std::array<uint32_t, 3>& dims :
       {std::array<uint32_t, 3>{1, 1, 1}, {7, 3, 5}, {64, 9, 4}, {1, 200, 3}, {300, 2, 2}}) {
    for (const bool ends : {false, true}) {
      const Grid grid = randomBand(seed++, dims, ends);
      ASSERT_FALSE(grid.sdfKeys.empty());
      const std::string bytes = encodeGridFile(box, grid);
      EXPECT_EQ(versionOf(bytes), 5u);
      const GridFile back = decodeGridFile(bytes, "v5.vgrid");
      expectSameBand(back.grid, grid);
      EXPECT_EQ(encodeGridFile(back.scene, back.grid), bytes);
      const std::string old = asVersion4(box, grid);
      EXPECT_EQ(versionOf(old), 4u);
      expectSameBand(decodeGridFile(old, "v4.vgrid").grid, grid);
      // Smaller but for a band of one cell: its 8-byte key becomes a byte count and two 1-byte varints.
      EXPECT_LE(bytes.size(), old.size() + (grid.sdfKeys.size() == 1 ? 2 : 0));
      if (grid.sdfKeys.size() > 1) {
        EXPECT_LT(bytes.size(), old.size());
      }
    }
  }
  // Every truncation inside the section is refused, never a crash.
  const Grid grid = randomBand(99, {9, 4, 3}, true);
  const std::string bytes = encodeGridFile(box, grid);
  for (size_t cut = bytes.size() - currentSection(box, grid).size() + 1; cut < bytes.size(); ++cut)
    EXPECT_THROW(decodeGridFile(resealed(bytes.substr(0, cut)), "cut.vgrid"), InputError) << cut;
}

TEST(GridSectionDistances, TheLastKeysOfTheLargestGrid) {
  Grid grid;
  grid.dims = {1u << 21, 1u << 21, 1u << 21};
  grid.bounds = {{0, 0, 0}, {1, 1, 1}};
  grid.sdfHalfWidth = 64;
  const uint64_t last = grid.cellCount() - 1;
  grid.sdfKeys = {0, 1, last - 2, last};
  grid.sdfValues = {-1e300, 0.0, 5e-324, 1e300};
  const Scene box = testing::boxScene(0.2, 0.8);
  expectSameBand(decodeGridFile(encodeGridFile(box, grid), "big.vgrid").grid, grid);
}

// tests/data/grid_v4/bunny_200_res12_sdf3_fraction.vgrid: `vox-voxelize data/6837/scenes/bunny_200.obj --res 12
// --sdf 3 --fraction` of the build before version 5 (a Distances section of flat keys, then the Fractions).
TEST(GridSectionDistances, Version4FileOfThePreviousBuildStillReads) {
  const std::string path = std::string(VOX_SOURCE_DIR) + "/tests/data/grid_v4/bunny_200_res12_sdf3_fraction.vgrid";
  const std::string bytes = testing::readAll(path);
  ASSERT_EQ(versionOf(bytes), 4u);
  const GridFile old = decodeGridFile(bytes, path);
  EXPECT_GT(old.grid.sdfKeys.size(), 300u);
  EXPECT_EQ(old.grid.fractions.size(), old.grid.occupiedCount());
  // This test's encoder of version 4 gives back the very bytes: every key and distance was read as written.
  EXPECT_EQ(asVersion4(old.scene, old.grid), bytes);
  const std::string now = encodeGridFile(old.scene, old.grid);
  EXPECT_EQ(versionOf(now), 5u);
  EXPECT_LT(now.size(), bytes.size());
  const GridFile again = decodeGridFile(now, "v5.vgrid");
  expectSameBand(again.grid, old.grid);
  EXPECT_EQ(again.grid.fractions, old.grid.fractions);
  EXPECT_EQ(again.grid.cellKeys, old.grid.cellKeys);
  // A grid with fractions only is still version 4, and one with neither version 3: their bytes are unchanged.
  Grid fractionsOnly = old.grid;
  fractionsOnly.sdfHalfWidth = 0;
  fractionsOnly.sdfKeys.clear();
  fractionsOnly.sdfValues.clear();
  EXPECT_EQ(versionOf(encodeGridFile(old.scene, fractionsOnly)), 4u);
  EXPECT_THROW(encodeGridFile(old.scene, old.grid, 4), UsageError);
}

// A version 5 body: half-width 3, `count`, the runs' bytes, then `values` distances.
std::string runsBody(uint64_t count, const std::vector<uint8_t>& runs, size_t values, uint64_t runBytes = ~0ull) {
  ByteWriter w;
  w.put(3.0);
  w.put(count);
  w.put(runBytes == ~0ull ? uint64_t(runs.size()) : runBytes);
  w.putBytes({reinterpret_cast<const char*>(runs.data()), runs.size()});
  for (size_t i = 0; i < values; ++i) w.put(0.25 * double(i));
  return w.bytes();
}

std::vector<uint8_t> varints(std::initializer_list<uint64_t> values) {
  std::vector<uint8_t> out;
  for (uint64_t v : values) appendVarint(out, v);
  return out;
}

TEST(GridSectionDistances, HostileBodiesAreRefusedInOneLine) {
  const Scene box = testing::boxScene(0.2, 0.8);
  Grid grid;  // 4 x 4 x 4 = 64 cells, no occupied cell: the band alone
  grid.dims = {4, 4, 4};
  grid.bounds = {{0, 0, 0}, {1, 1, 1}};
  grid.sdfHalfWidth = 3;
  grid.sdfKeys = {0, 1, 2, 5, 63};
  grid.sdfValues = {0, 0.25, 0.5, 0.75, 1};
  const std::string file = encodeGridFile(box, grid);
  // The writer's own runs, written by hand: (0, 2), (2, 0), (57, 0).
  EXPECT_EQ(withBody(file, box, grid, runsBody(5, varints({0, 2, 2, 0, 57, 0}), 5)), file);
  const uint64_t huge = uint64_t(1) << 62;
  struct Case {
    std::string body;
    const char* says;
  };
  const std::vector<uint8_t> over = {0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x02};
  for (const Case& c : {
           Case{runsBody(1, varints({64, 0}), 1), "outside the grid"},
           Case{runsBody(1, varints({huge, 0}), 1), "outside the grid"},
           Case{runsBody(6, varints({60, 5}), 6), "outside the grid"},
           Case{runsBody(2, varints({63, 0, 1, 0}), 2), "outside the grid"},
           Case{runsBody(2, varints({0, 0, 0, 0}), 2), "runs touch"},
           Case{runsBody(3, varints({0, 5}), 3), "more cells than"},
           Case{runsBody(3, varints({0, 1}), 3), "truncated number"},
           Case{runsBody(2, varints({0, 1, 0}), 2), "bytes left"},
           Case{runsBody(1, {0x80}, 1), "truncated number"},
           Case{runsBody(1, {0x80, 0x00, 0x00}, 1), "shortest form"},
           Case{runsBody(1, over, 1), "too large"},
           Case{runsBody(huge, varints({0, 0}), 1), "exceeds the file"},
           Case{runsBody(~0ull >> 1, varints({0, 0}), 1), "exceeds the file"},
           Case{runsBody(65, varints({0, 64}), 65), "exceeds the file or the grid"},
           Case{runsBody(1, varints({0, 0}), 1, huge), "truncated"},
           Case{runsBody(2, varints({0, 1}), 1), "exceeds the file"},
       }) {
    try {
      decodeGridFile(withBody(file, box, grid, c.body), "bad.vgrid");
      ADD_FAILURE() << "accepted: " << c.says;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.says), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_EQ(what.rfind("bad.vgrid: ", 0), 0u) << what;
    }
  }
  // A distance that is not finite.
  std::string nan = runsBody(5, varints({0, 2, 2, 0, 57, 0}), 5);
  const double notANumber = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&nan[nan.size() - 16], &notANumber, 8);
  EXPECT_THROW(decodeGridFile(withBody(file, box, grid, nan), "nan.vgrid"), InputError);
  // The flat keys of version 4 are checked as before.
  Grid unsorted = grid;
  std::swap(unsorted.sdfKeys[1], unsorted.sdfKeys[2]);
  EXPECT_THROW(decodeGridFile(withBody(file, box, grid, version4Body(unsorted), 4), "v4.vgrid"), InputError);
  Grid outside = grid;
  outside.sdfKeys.back() = 64;
  EXPECT_THROW(decodeGridFile(withBody(file, box, grid, version4Body(outside), 4), "v4.vgrid"), InputError);
  // Version 5's runs in a version 4 file read as flat keys: refused, not misread.
  EXPECT_THROW(decodeGridFile(withBody(file, box, grid, runsBody(5, varints({0, 2, 2, 0, 57, 0}), 5), 4), "x"),
               InputError);
}

TEST(GridSectionDistances, ALongBandAsksProgressInOrderAndCancels) {
  Grid grid;
  grid.dims = {256, 64, 32};
  grid.bounds = {{0, 0, 0}, {1, 1, 1}};
  grid.sdfHalfWidth = 2;
  for (uint64_t k = 0; k + 2 < grid.cellCount() - 1; k += 3) {
    grid.sdfKeys.push_back(k);
    grid.sdfKeys.push_back(k + 1);
    grid.sdfValues.push_back(double(k));
    grid.sdfValues.push_back(-double(k));
  }
  grid.sdfKeys.push_back(grid.cellCount() - 1);
  grid.sdfValues.push_back(1);
  const Scene box = testing::boxScene(0.2, 0.8);
  for (const uint32_t version : {4u, 5u}) {
    const std::string bytes = version == 5 ? encodeGridFile(box, grid) : asVersion4(box, grid);
    ASSERT_EQ(versionOf(bytes), version);
    std::vector<double> asked;
    const GridFile back = decodeGridFile(bytes, "long.vgrid", [&](double f) {
      asked.push_back(f);
      return true;
    });
    expectSameBand(back.grid, grid);
    // Once per 2^16 keys and per 2^16 distances at least.
    EXPECT_GE(asked.size(), 2 * (grid.sdfKeys.size() >> 16)) << version;
    for (size_t i = 0; i < asked.size(); ++i) {
      EXPECT_TRUE(asked[i] >= 0 && asked[i] <= 1) << asked[i];
      if (i > 0) {
        EXPECT_GE(asked[i], asked[i - 1]) << version << " " << i;
      }
    }
    size_t calls = 0;
    EXPECT_THROW(decodeGridFile(bytes, "long.vgrid", [&](double) { return ++calls < asked.size() / 2; }), Error);
    EXPECT_EQ(calls, asked.size() / 2);
  }
}

}  // namespace
}  // namespace vox
