// Grid file version 3's cell table (io/grid_cell_table.cpp): the same cells and ids as version 2's flat arrays for
// every method, old files still read as they were written, extremes of keys and ids, and every malformed table
// refused with the byte it fails at, before any allocation the file cannot back.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <limits>

#include "io/byte_codec.h"
#include "io/grid_cell_table.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

void expectSameCells(const Grid& a, const Grid& b) {
  EXPECT_EQ(a.cellKeys, b.cellKeys);
  EXPECT_EQ(a.cellStart, b.cellStart);
  EXPECT_EQ(a.primIds, b.primIds);
}

// Encodes `grid`'s table alone and decodes it into a grid of the same dims, with ids below `bounded`.
Grid tableRoundTrip(const Grid& grid, uint64_t bounded) {
  ByteWriter w;
  putCellTable(w, encodeCellTable(grid));
  const std::string bytes = w.bytes();
  ByteReader r(bytes, 0, "t.vgrid");
  Grid back;
  back.dims = grid.dims;
  getCellTable(r, back, bounded);
  EXPECT_TRUE(r.atEnd());
  return back;
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(GridCellTable, SameCellsAsVersion2ForEveryMethodAndFill) {
  const Scene scene = testing::randomScene(5, 60, 4);
  for (const OverlapMethod method :
       {OverlapMethod::Center, OverlapMethod::BBox, OverlapMethod::Sat, OverlapMethod::Exact}) {
    for (const bool fill : {false, true}) {
      VoxelizeOptions opt;
      opt.dims = {23, 17, 11};
      opt.method = method;
      Grid grid = voxelizeScene(scene, opt);
      if (fill) fillSolid(grid, scene, {});
      const GridFile v3 = decodeGridFile(encodeGridFile(scene, grid), "v3.vgrid");
      const GridFile v2 = decodeGridFile(encodeGridFile(scene, grid, 2), "v2.vgrid");
      expectSameCells(v3.grid, grid);
      expectSameCells(v2.grid, grid);
      EXPECT_EQ(v3.grid.solidRuns.size(), grid.solidRuns.size());
      // What a version 3 file holds re-encodes to the same version 2 bytes, and back.
      EXPECT_EQ(encodeGridFile(v3.scene, v3.grid, 2), encodeGridFile(scene, grid, 2));
      EXPECT_EQ(encodeGridFile(v2.scene, v2.grid), encodeGridFile(scene, grid));
    }
  }
}

// Files written by the previous version (tests/data/grid_v2/, made by vox-voxelize before version 3) read as what
// today's voxelizer makes of the same scenes, and re-encode to their own bytes as version 2.
TEST(GridCellTable, Version2FilesOfThePreviousBuildStillRead) {
  const std::string data = std::string(VOX_SOURCE_DIR) + "/tests/data/grid_v2/";
  struct Case {
    const char* file;
    const char* scene;
    uint32_t resolution;
    OverlapMethod method;
    bool fill;
  };
  for (const Case& c :
       {Case{"scene5_05_res12_fill.vgrid", "scene5_05_sphere_triangles.txt", 12, OverlapMethod::Exact, true},
        Case{"bunny_1k_res16_sat.vgrid", "bunny_1k.obj", 16, OverlapMethod::Sat, false}}) {
    const std::string bytes = readBytes(data + c.file);
    uint32_t version = 0;
    std::memcpy(&version, bytes.data() + 8, 4);
    ASSERT_EQ(version, 2u) << c.file;
    const GridFile old = decodeGridFile(bytes, c.file);
    EXPECT_EQ(encodeGridFile(old.scene, old.grid, 2), bytes) << c.file;
    const Scene scene = loadScene(std::string(VOX_SOURCE_DIR) + "/scenes/" + c.scene);
    VoxelizeOptions opt;
    opt.resolution = c.resolution;
    opt.method = c.method;
    Grid grid = voxelizeScene(scene, opt);
    if (c.fill) fillSolid(grid, scene, {});
    expectSameCells(old.grid, grid);
    EXPECT_EQ(old.grid.solidCount(), grid.solidCount()) << c.file;
    EXPECT_GT(old.grid.cellKeys.size(), 50u) << c.file;
  }
}

TEST(GridCellTable, ExtremeKeysAndIds) {
  // The last cell of a 2^21-per-axis grid (key 2^63 - 1), the first, and ids at the top of u32.
  Grid grid;
  grid.dims = {1u << 21, 1u << 21, 1u << 21};
  const uint64_t last = grid.cellCount() - 1;
  const uint32_t top = std::numeric_limits<uint32_t>::max();
  grid.cellKeys = {0, 1, last - 1, last};
  grid.cellStart = {0, 2, 3, 5, 6};
  grid.primIds = {0, top, top, 7, top - 1, 0};
  const uint64_t bounded = uint64_t(top) + 1;
  expectSameCells(tableRoundTrip(grid, bounded), grid);
  // A 1x1x1 grid with one cell, and an empty grid.
  Grid one;
  one.dims = {1, 1, 1};
  one.cellKeys = {0};
  one.cellStart = {0, 1};
  one.primIds = {3};
  expectSameCells(tableRoundTrip(one, 4), one);
  Grid empty;
  empty.dims = {4, 4, 4};
  expectSameCells(tableRoundTrip(empty, 0), empty);
  // An id at the limit is refused, not wrapped.
  EXPECT_THROW(tableRoundTrip(one, 3), InputError);
  EXPECT_THROW(tableRoundTrip(grid, top), InputError);
}

TEST(GridCellTable, SmallerThanVersion2) {
  // The table is what makes version 3 small: most cells of a surface are one byte of key and count and a few
  // bytes of ids, against 16 bytes per cell and 4 per id.
  const Scene scene = loadScene(std::string(VOX_SOURCE_DIR) + "/scenes/bunny_1k.obj");
  VoxelizeOptions opt;
  opt.resolution = 128;
  const Grid grid = voxelizeScene(scene, opt);
  const EncodedCellTable table = encodeCellTable(grid);
  const uint64_t flat = grid.cellKeys.size() * 16 + grid.primIds.size() * 4 + 8;
  EXPECT_LT(table.bytes.size() * 3, flat) << table.bytes.size() << " against " << flat;
  EXPECT_LT(encodeGridFile(scene, grid).size() * 2, encodeGridFile(scene, grid, 2).size());
}

// A table's bytes after its three counts, re-headed: lets each test craft exactly one defect.
std::string table(uint64_t occupied, uint64_t references, const std::vector<uint8_t>& body) {
  ByteWriter w;
  w.put(occupied);
  w.put(references);
  w.put(uint64_t(body.size()));
  w.putBytes({reinterpret_cast<const char*>(body.data()), body.size()});
  return w.bytes();
}

void expectRefused(const std::string& bytes, const char* what, uint64_t bounded = 10) {
  ByteReader r(bytes, 0, "bad.vgrid");
  Grid grid;
  grid.dims = {4, 4, 4};
  try {
    getCellTable(r, grid, bounded);
    ADD_FAILURE() << "accepted: " << what;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.vgrid: cell table at byte"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(GridCellTable, MalformedTablesAreRefusedAtTheirByte) {
  // Sanity: key 5, one id 2; key 7 (gap 1), ids 3, 4.
  {
    const std::string good = table(2, 3, {5, 0, 4, 1, 1, 2, 0});
    ByteReader r(good, 0, "good.vgrid");
    Grid grid;
    grid.dims = {4, 4, 4};
    getCellTable(r, grid, 10);
    EXPECT_EQ(grid.cellKeys, (HugeVector<uint64_t>{5, 7}));
    EXPECT_EQ(grid.primIds, (HugeVector<uint32_t>{2, 3, 4}));
  }
  expectRefused(table(2, 3, {5, 0, 4, 58, 1, 2, 0}), "cell key outside the grid");       // 5 + 1 + 58 = 64
  expectRefused(table(1, 1, {64, 0, 0}), "cell key outside the grid");                   // past the last cell
  expectRefused(table(1, 1, {0x85, 0x00, 0, 0}), "shortest form");                       // 5 written in two bytes
  expectRefused(table(1, 2, {5, 1, 4, 0x85}), "truncated");                              // varint cut short
  expectRefused(table(1, 2, {5, 1, 4, 0xff, 0xff, 0xff, 0xff, 0x0f}), "not ascending");  // id past 2^32
  expectRefused(table(1, 1, {5, 0, 20}), "primitive id out of range");                   // id 10 with 10 bounded
  expectRefused(table(1, 1, {5, 0, 1}), "primitive id out of range");                    // id -1
  expectRefused(table(1, 1, {5, 1, 4}), "more references");                              // 2 ids, 1 counted
  expectRefused(table(1, 2, {5, 0, 4, 0}), "fewer references");                          // 1 id, 2 counted
  expectRefused(table(1, 1, {5, 0, 4, 0}), "bytes left");
  // Absurd counts are refused from the three counts alone, before the arrays are sized.
  expectRefused(table(uint64_t(1) << 60, 1, {5, 0, 4}), "do not fit");
  expectRefused(table(1, uint64_t(1) << 60, {5, 0, 4}), "do not fit");
  // A size past the end of the file.
  std::string cut = table(1, 1, {5, 0, 4});
  cut.pop_back();
  ByteReader r(cut, 0, "bad.vgrid");
  Grid grid;
  EXPECT_THROW(getCellTable(r, grid, 10), InputError);
}

}  // namespace
}  // namespace vox
