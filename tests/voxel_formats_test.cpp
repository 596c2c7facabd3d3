// Tests of the voxel file writers (binvox_writer, magicavoxel_writer, vdb_writer, voxel_runs, voxel_format). Each
// file is read back by a reader written here from the published descriptions (binvox: Patrick Min's page and
// binvox-rw-py; .vox: ephtracy/voxel-model's two format texts), or, for .vdb, by OpenVDB itself; the voxel sets read
// back must equal the grid's occupied and solid cells, cell for cell.
#include <gtest/gtest.h>

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <sstream>

#include "../fuzz/voxel_writers_entry.h"
#include "test_util.h"
#include "vox/core/error.h"
#include "vox/export/binvox_writer.h"
#include "vox/export/magicavoxel_writer.h"
#include "vox/export/vdb_writer.h"
#include "vox/export/voxel_format.h"
#include "vox/export/voxel_runs.h"
#include "vox/io/grid_set.h"

namespace vox {
namespace {

using Cell = std::array<uint32_t, 3>;

// A random grid: occupied cells (each with 1..3 primitives) and solid runs, some overlapping occupied cells and
// crossing rows, over non-cubic cells.
Grid randomGrid(const std::array<uint32_t, 3>& dims, uint32_t seed, int occupied, int runs) {
  std::mt19937_64 rng(seed);
  Grid g;
  g.dims = dims;
  g.bounds = {{-1.5, 2, 0.25}, {-1.5 + 0.5 * dims[0], 2 + 0.25 * dims[1], 0.25 + 0.75 * dims[2]}};
  const uint64_t cells = g.cellCount();
  std::set<uint64_t> keys;
  for (int i = 0; i < occupied; ++i) keys.insert(rng() % cells);
  g.cellKeys.assign(keys.begin(), keys.end());
  for (size_t c = 0; c < g.cellKeys.size(); ++c) {
    for (uint32_t p = 0; p <= c % 3; ++p) g.primIds.push_back(p);
    g.cellStart.push_back(g.primIds.size());
  }
  std::set<uint64_t> starts;
  for (int r = 0; r < runs; ++r) starts.insert(rng() % cells);
  uint64_t end = 0;
  for (uint64_t s : starts) {
    if (s <= end && !g.solidRuns.empty()) continue;
    const uint64_t n = std::min<uint64_t>(1 + rng() % (3 * dims[0]), cells - s);
    g.solidRuns.push_back({s, n});
    end = s + n;
  }
  return g;
}

// The voxels, by brute force over keys.
std::set<Cell> voxelSet(const Grid& g) {
  std::set<Cell> out;
  for (uint64_t k : g.cellKeys) out.insert(cellIndex(g.dims, k));
  for (const CellRun& r : g.solidRuns)
    for (uint64_t k = r.first; k < r.first + r.count; ++k) out.insert(cellIndex(g.dims, k));
  return out;
}

TEST(VoxelRuns, UnionOfOccupiedAndSolidCellsInKeyOrderCutAtRows) {
  const Grid g = randomGrid({37, 11, 9}, 1, 400, 30);
  std::set<Cell> seen;
  uint64_t lastEnd = 0;
  bool first = true;
  forEachVoxelRow(g, [&](const VoxelRow& r) {
    ASSERT_GE(r.count, 1u);
    ASSERT_LE(r.i0 + r.count, g.dims[0]);
    ASSERT_EQ(r.key, cellKey(g.dims, r.i0, r.j, r.k));
    // Maximal: a run that does not start a row never touches the previous one.
    if (!first && r.i0 > 0) {
      ASSERT_GT(r.key, lastEnd);
    }
    if (!first) {
      ASSERT_GE(r.key, lastEnd);
    }
    first = false;
    lastEnd = r.key + r.count;
    for (uint32_t c = 0; c < r.count; ++c) ASSERT_TRUE(seen.insert({r.i0 + c, r.j, r.k}).second);
  });
  EXPECT_EQ(seen, voxelSet(g));
  EXPECT_EQ(countVoxels(g), seen.size());
}

TEST(VoxelRuns, RefusesUnsortedKeysAndBadRuns) {
  Grid g = randomGrid({8, 8, 8}, 2, 20, 3);
  Grid bad = g;
  std::swap(bad.cellKeys[0], bad.cellKeys[1]);
  EXPECT_THROW(countVoxels(bad), InputError);
  bad = g;
  bad.cellKeys.back() = g.cellCount();
  EXPECT_THROW(countVoxels(bad), InputError);
  bad = g;
  bad.solidRuns.push_back({g.cellCount() - 1, 5});
  EXPECT_THROW(countVoxels(bad), InputError);
}

// ---- binvox, read as binvox-rw-py does: header lines, then (value, count) pairs over x*D*D + z*D + y.
struct Binvox {
  uint32_t dims[3] = {0, 0, 0};
  double translate[3] = {0, 0, 0};
  double scale = 0;
  std::set<Cell> voxels;  // (x, y, z)
  uint64_t decoded = 0;   // cells covered by the runs
};

Binvox readBinvox(const std::string& bytes) {
  Binvox b;
  std::istringstream in(bytes);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "#binvox 1");
  while (std::getline(in, line) && line != "data") {
    std::istringstream l(line);
    std::string key;
    l >> key;
    if (key == "dim") l >> b.dims[0] >> b.dims[1] >> b.dims[2];
    if (key == "translate") l >> b.translate[0] >> b.translate[1] >> b.translate[2];
    if (key == "scale") l >> b.scale;
  }
  EXPECT_EQ(line, "data");
  const uint64_t d = b.dims[0];
  char pair[2];
  while (in.read(pair, 2)) {
    const uint8_t value = uint8_t(pair[0]), count = uint8_t(pair[1]);
    EXPECT_TRUE(value == 0 || value == 1);
    EXPECT_GE(count, 1);
    for (uint32_t c = 0; c < count; ++c, ++b.decoded) {
      if (!value) continue;
      const uint64_t x = b.decoded / (d * d), z = (b.decoded / d) % d, y = b.decoded % d;
      b.voxels.insert({uint32_t(x), uint32_t(y), uint32_t(z)});
    }
  }
  EXPECT_EQ(in.gcount(), 0) << "odd byte at the end";
  return b;
}

TEST(Binvox, ReadBackEqualsTheGridsVoxels) {
  for (const auto& dims : {std::array<uint32_t, 3>{37, 11, 9}, {5, 70, 23}, {1, 1, 1}, {130, 3, 129}}) {
    const Grid g = randomGrid(dims, dims[0] * 7 + dims[1], 300, 25);
    std::ostringstream out;
    const BinvoxLayout layout = writeBinvox(out, g);
    const Binvox b = readBinvox(out.str());
    const uint32_t d = std::max({dims[0], dims[1], dims[2]});
    EXPECT_EQ(b.dims[0], d);
    EXPECT_EQ(b.dims[1], d);
    EXPECT_EQ(b.dims[2], d);
    EXPECT_EQ(b.decoded, uint64_t(d) * d * d);
    EXPECT_EQ(b.voxels, voxelSet(g));
    for (int a = 0; a < 3; ++a) EXPECT_EQ(b.translate[a], g.bounds.lo[a]);
    EXPECT_EQ(b.scale, layout.scale);
    EXPECT_DOUBLE_EQ(layout.scale, layout.voxelSide * d);
  }
}

TEST(Binvox, CubicCellsMapExactlyAndNonCubicOnesReportTheShift) {
  Grid g = randomGrid({20, 10, 5}, 3, 50, 2);
  g.bounds = {{0, 0, 0}, {2, 1, 0.5}};  // cells of 0.1 on every axis
  BinvoxLayout l = binvoxLayout(g);
  EXPECT_DOUBLE_EQ(l.voxelSide, 0.1);
  EXPECT_NEAR(l.farFaceShiftVoxels, 0, 1e-9);
  g.bounds = {{0, 0, 0}, {2, 1.1, 0.5}};  // y cells of 0.11: the far y face moves by 10 * 0.01 / 0.1 = 1 voxel
  l = binvoxLayout(g);
  EXPECT_NEAR(l.farFaceShiftVoxels, 1.0, 1e-9);
  g.dims = {kBinvoxMaxDim + 1, 1, 1};
  g.cellKeys.clear(), g.cellStart = {0}, g.primIds.clear(), g.solidRuns.clear();
  EXPECT_THROW(binvoxLayout(g), LimitError);
}

// ---- MagicaVoxel, read from the format texts: RIFF chunks, SIZE/XYZI models, nTRN/nGRP/nSHP, RGBA.
struct VoxFile {
  struct Model {
    uint32_t size[3];
    std::vector<std::array<uint8_t, 4>> voxels;
  };
  std::vector<Model> models;
  std::map<uint32_t, std::array<int64_t, 3>> modelTranslation;  // model id -> "_t" of its transform
  std::array<std::array<uint8_t, 4>, 256> palette{};            // palette[i] is colour index i + 1
};

struct ByteReader {
  const std::string& s;
  size_t at = 0;
  uint32_t u32() {
    EXPECT_LE(at + 4, s.size());
    uint32_t v = 0;
    for (int b = 0; b < 4; ++b) v |= uint32_t(uint8_t(s[at + b])) << (8 * b);
    at += 4;
    return v;
  }
  std::string str() {
    const uint32_t n = u32();
    std::string v = s.substr(at, n);
    at += n;
    return v;
  }
  std::map<std::string, std::string> dict() {
    std::map<std::string, std::string> d;
    for (uint32_t n = u32(); n > 0; --n) {
      std::string k = str();
      d[k] = str();
    }
    return d;
  }
};

VoxFile readVox(const std::string& bytes) {
  VoxFile f;
  ByteReader r{bytes};
  EXPECT_EQ(bytes.substr(0, 4), "VOX ");
  r.at = 4;
  EXPECT_EQ(r.u32(), 150u);
  EXPECT_EQ(bytes.substr(8, 4), "MAIN");
  r.at = 12;
  EXPECT_EQ(r.u32(), 0u);
  const uint32_t children = r.u32();
  EXPECT_EQ(uint64_t(children) + 20, bytes.size());
  std::map<uint32_t, std::pair<uint32_t, std::array<int64_t, 3>>> transforms;  // node -> child, translation
  std::map<uint32_t, uint32_t> shapes;                                         // node -> model
  while (r.at + 12 <= bytes.size()) {
    const std::string id = bytes.substr(r.at, 4);
    r.at += 4;
    const uint32_t content = r.u32();
    EXPECT_EQ(r.u32(), 0u);
    const size_t next = r.at + content;
    if (id == "SIZE") {
      VoxFile::Model m;
      for (auto& s : m.size) s = r.u32();
      f.models.push_back(m);
    } else if (id == "XYZI") {
      const uint32_t n = r.u32();
      EXPECT_EQ(content, 4 + 4 * n);
      for (uint32_t v = 0; v < n; ++v) {
        std::array<uint8_t, 4> x;
        std::memcpy(x.data(), bytes.data() + r.at, 4);
        r.at += 4;
        f.models.back().voxels.push_back(x);
      }
    } else if (id == "nTRN") {
      const uint32_t node = r.u32();
      r.dict();
      const uint32_t child = r.u32();
      EXPECT_EQ(r.u32(), uint32_t(-1));
      r.u32();  // layer
      EXPECT_EQ(r.u32(), 1u);
      auto frame = r.dict();
      std::array<int64_t, 3> t{0, 0, 0};
      if (frame.count("_t")) {
        std::istringstream ts(frame["_t"]);
        ts >> t[0] >> t[1] >> t[2];
      }
      transforms[node] = {child, t};
    } else if (id == "nGRP") {
      r.u32();
      r.dict();
      for (uint32_t n = r.u32(); n > 0; --n) r.u32();
    } else if (id == "nSHP") {
      const uint32_t node = r.u32();
      r.dict();
      EXPECT_EQ(r.u32(), 1u);
      shapes[node] = r.u32();
      r.dict();
    } else if (id == "RGBA") {
      for (auto& c : f.palette)
        for (auto& ch : c) ch = uint8_t(bytes[r.at++]);
    }
    EXPECT_EQ(r.at, next) << id;
    r.at = next;
  }
  EXPECT_EQ(r.at, bytes.size());
  for (const auto& [node, ct] : transforms)
    if (shapes.count(ct.first)) f.modelTranslation[shapes[ct.first]] = ct.second;
  return f;
}

// World voxel positions of a .vox file: the model's voxel v sits at translation + v - floor(size / 2).
std::map<Cell, Rgb8> voxWorld(const VoxFile& f) {
  std::map<Cell, Rgb8> out;
  for (uint32_t m = 0; m < f.models.size(); ++m) {
    const auto& model = f.models[m];
    EXPECT_TRUE(f.modelTranslation.count(m)) << "model " << m << " placed by no transform";
    const auto t = f.modelTranslation.at(m);
    for (int a = 0; a < 3; ++a) EXPECT_LE(model.size[a], 256u);
    for (const auto& v : model.voxels) {
      Cell c;
      for (int a = 0; a < 3; ++a) {
        EXPECT_LT(v[a], model.size[a]);
        c[a] = uint32_t(t[a] + v[a] - model.size[a] / 2);
      }
      EXPECT_GE(v[3], 1);
      const auto& p = f.palette[v[3] - 1];
      EXPECT_TRUE(out.insert({c, Rgb8{p[0], p[1], p[2]}}).second);
    }
  }
  return out;
}

TEST(MagicaVoxel, ReadBackEqualsTheGridsVoxelsAndColoursAcrossModels) {
  // 300 x 5 x 520: 2 x 1 x 3 tiles, some empty.
  const Grid g = randomGrid({300, 5, 520}, 4, 3000, 60);
  std::vector<Rgb8> colors;
  for (size_t c = 0; c < g.cellKeys.size(); ++c) colors.push_back({uint8_t(c % 7 * 30), uint8_t(c % 5), 200});
  std::ostringstream out;
  const MagicaVoxelStats s = writeMagicaVoxel(out, g, colors, kSolidCellColor);
  const VoxFile f = readVox(out.str());
  const auto world = voxWorld(f);
  std::set<Cell> cells;
  for (const auto& [c, col] : world) cells.insert(c);
  EXPECT_EQ(cells, voxelSet(g));
  EXPECT_EQ(s.voxels, cells.size());
  EXPECT_EQ(s.models, f.models.size());
  EXPECT_GE(f.models.size(), 4u);
  EXPECT_FALSE(s.paletteReduced);
  for (size_t c = 0; c < g.cellKeys.size(); ++c) EXPECT_EQ(world.at(cellIndex(g.dims, g.cellKeys[c])), colors[c]);
  for (const Cell& c : cells)
    if (findCell(g, cellKey(g.dims, c[0], c[1], c[2])) < 0) {
      EXPECT_EQ(world.at(c), kSolidCellColor);
    }
}

TEST(MagicaVoxel, NoColoursAndEmptyGrid) {
  const Grid g = randomGrid({20, 20, 20}, 5, 100, 5);
  std::ostringstream out;
  writeMagicaVoxel(out, g, {}, kSolidCellColor);
  const auto world = voxWorld(readVox(out.str()));
  EXPECT_EQ(world.size(), voxelSet(g).size());
  for (const auto& [c, col] : world) EXPECT_EQ(col, kSolidCellColor);
  Grid empty;
  empty.dims = {4, 4, 4};
  empty.bounds = {{0, 0, 0}, {1, 1, 1}};
  std::ostringstream e;
  EXPECT_EQ(writeMagicaVoxel(e, empty, {}, kSolidCellColor).models, 0u);
  EXPECT_TRUE(readVox(e.str()).models.empty());
  EXPECT_THROW(writeMagicaVoxel(e, g, std::vector<Rgb8>(3), kSolidCellColor), InputError);
}

TEST(MagicaVoxel, MoreThan255ColoursGetTheNearestOf255) {
  const Grid g = randomGrid({64, 64, 64}, 6, 5000, 0);
  std::vector<Rgb8> colors;
  std::mt19937 rng(7);
  for (size_t c = 0; c < g.cellKeys.size(); ++c) colors.push_back({uint8_t(rng()), uint8_t(rng()), uint8_t(rng())});
  std::ostringstream out;
  const MagicaVoxelStats s = writeMagicaVoxel(out, g, colors, kSolidCellColor);
  EXPECT_TRUE(s.paletteReduced);
  EXPECT_EQ(s.paletteColors, 255u);
  const VoxFile f = readVox(out.str());
  const auto world = voxWorld(f);
  auto dist = [](const Rgb8& a, const std::array<uint8_t, 4>& b) {
    int d = 0;
    for (int ch = 0; ch < 3; ++ch) d += (int(a[ch]) - b[ch]) * (int(a[ch]) - b[ch]);
    return d;
  };
  for (size_t c = 0; c < g.cellKeys.size(); ++c) {
    const Rgb8 got = world.at(cellIndex(g.dims, g.cellKeys[c]));
    int best = INT32_MAX;
    for (int p = 0; p < 255; ++p) best = std::min(best, dist(colors[c], f.palette[p]));
    EXPECT_EQ(dist(colors[c], {got[0], got[1], got[2], 255}), best);
  }
}

TEST(MagicaVoxel, RefusesFilesBeyondTheInt32ChunkSizes) {
  Grid g;
  g.dims = {2048, 2048, 2048};
  g.bounds = {{0, 0, 0}, {1, 1, 1}};
  g.solidRuns.push_back({0, uint64_t(600) << 20});  // 629 M voxels: 2.5 GB of XYZI
  std::ostringstream out;
  EXPECT_THROW(writeMagicaVoxel(out, g, {}, kSolidCellColor), LimitError);
  EXPECT_TRUE(out.str().empty());
}

TEST(Palette, AtMost255DistinctColoursAreKeptExactly) {
  std::vector<Rgb8> c{{3, 2, 1}, {0, 0, 0}, {255, 255, 255}};
  std::vector<uint64_t> w{1, 5, 2};
  EXPECT_EQ(choosePalette(c, w), (std::vector<Rgb8>{{0, 0, 0}, {3, 2, 1}, {255, 255, 255}}));
}

// ---- OpenVDB, read back by OpenVDB.
TEST(Vdb, DensityAndCountReadBackByOpenVdbInWorldSpace) {
  const Grid g = randomGrid({40, 17, 30}, 8, 700, 40);
  std::ostringstream out;
  const VdbStats s = writeVdb(out, g);
  const std::set<Cell> cells = voxelSet(g);
  EXPECT_EQ(s.activeVoxels, cells.size());
  std::istringstream in(out.str());
  openvdb::initialize();
  openvdb::io::Stream stream(in);
  openvdb::GridPtrVecPtr grids = stream.getGrids();
  ASSERT_EQ(grids->size(), 2u);
  auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(openvdb::findGridByName(*grids, "density"));
  auto count = openvdb::gridPtrCast<openvdb::FloatGrid>(openvdb::findGridByName(*grids, "count"));
  ASSERT_TRUE(density && count);
  EXPECT_EQ(density->activeVoxelCount(), cells.size());
  EXPECT_EQ(count->activeVoxelCount(), g.cellKeys.size());
  auto acc = density->getConstAccessor();
  for (const Cell& c : cells) {
    const openvdb::Coord ijk{int(c[0]), int(c[1]), int(c[2])};
    ASSERT_TRUE(acc.isValueOn(ijk));
    ASSERT_EQ(acc.getValue(ijk), 1.0f);
  }
  for (size_t c = 0; c < g.cellKeys.size(); ++c) {
    const Cell ijk = cellIndex(g.dims, g.cellKeys[c]);
    EXPECT_EQ(count->tree().getValue(openvdb::Coord(int(ijk[0]), int(ijk[1]), int(ijk[2]))),
              float(g.cellStart[c + 1] - g.cellStart[c]));
  }
  // Index (i, j, k) is the centre of cell (i, j, k); the cell's corners are the grid's boundaries.
  const openvdb::Vec3d centre = density->transform().indexToWorld(openvdb::Vec3d(3, 5, 7));
  const Box cell = cellBox(g, 3, 5, 7);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(centre[a], 0.5 * (cell.lo[a] + cell.hi[a]), 1e-12);
  const openvdb::Vec3d corner = density->transform().indexToWorld(openvdb::Vec3d(-0.5, -0.5, -0.5));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(corner[a], g.bounds.lo[a], 1e-12);
}

TEST(Vdb, LongSolidRunsBecomeTiles) {
  Grid g;
  g.dims = {256, 256, 256};
  g.bounds = {{0, 0, 0}, {1, 1, 1}};
  for (uint32_t k = 0; k < 256; ++k)  // a full 256^3 block but for one corner cell per layer
    g.solidRuns.push_back({cellKey(g.dims, 1, 0, k), 256 * 256 - 1});
  std::ostringstream out;
  const VdbStats s = writeVdb(out, g);
  EXPECT_EQ(s.activeVoxels, g.solidCount());
  EXPECT_EQ(s.leafNodes, 32u);  // only the 32 leaves holding the missing column (0, 0, k) stay leaves
}

// Boxes, rectangles and layers of changing shape: the density builder merges rows into boxes; the voxels must stay
// exactly the grid's.
TEST(Vdb, MergedBoxesKeepTheExactVoxels) {
  Grid g;
  g.dims = {40, 30, 50};
  g.bounds = {{0, 0, 0}, {4, 3, 5}};
  for (uint32_t k = 0; k < 50; ++k)
    for (uint32_t j = 0; j < 30; ++j) {
      const bool box = k >= 2 && k < 31 && j >= 3 && j < 27;  // a 29-layer box of x 5..34
      const uint32_t w = 1 + (j * 7 + k * 3) % 11;            // and rows that change every layer
      const uint32_t i0 = box ? 5 : (k % 4 == 1 ? 0 : 2), n = box ? 30 : w;
      if (k % 9 == 8 && !box) continue;  // empty layers
      g.solidRuns.push_back({cellKey(g.dims, i0, j, k), n});
    }
  std::ostringstream out;
  const VdbStats s = writeVdb(out, g);
  std::istringstream in(out.str());
  openvdb::initialize();
  openvdb::io::Stream stream(in);
  auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(openvdb::findGridByName(*stream.getGrids(), "density"));
  ASSERT_TRUE(density);
  const std::set<Cell> cells = voxelSet(g);
  EXPECT_EQ(s.activeVoxels, cells.size());
  EXPECT_EQ(density->activeVoxelCount(), cells.size());
  for (const Cell& c : cells) ASSERT_TRUE(density->tree().isValueOn(openvdb::Coord{int(c[0]), int(c[1]), int(c[2])}));
}

TEST(VoxelFormat, ExtensionsAndFilesThroughTheOutputFile) {
  EXPECT_EQ(voxelFormatFromPath("a/b.BINVOX"), VoxelFormat::Binvox);
  EXPECT_EQ(voxelFormatFromPath("b.vox"), VoxelFormat::MagicaVoxel);
  EXPECT_EQ(voxelFormatFromPath("b.Vdb"), VoxelFormat::Vdb);
  EXPECT_FALSE(voxelFormatFromPath("b.ply").has_value());
  testing::ScratchDir dir("voxel_formats");
  const Grid g = randomGrid({10, 12, 14}, 9, 100, 4);
  for (auto f : {VoxelFormat::Binvox, VoxelFormat::MagicaVoxel, VoxelFormat::Vdb}) {
    const VoxelFileReport r = writeVoxelFile(dir.file("out"), f, g, {});
    EXPECT_EQ(r.voxels, voxelSet(g).size());
  }
  EXPECT_THROW(writeVoxelFile(dir.file("missing/out.vox"), VoxelFormat::MagicaVoxel, g, {}), OutputError);
}

// ---- Crafted grids of few runs over many cells (issue 23): each writer answers or refuses at once, in time and
// memory bounded by the runs, with the estimate in its message.

// A grid of n^3 cells, every one of them solid, in one run (what a 906-byte grid file can hold at n = 2^21).
Grid oneRunGrid(uint32_t n) {
  Grid g;
  g.dims = {n, n, n};
  g.bounds = {{0, 0, 0}, {double(n), double(n), double(n)}};
  g.solidRuns.push_back({0, g.cellCount()});
  return g;
}

// VOX_MEMORY_LIMIT_MB for the test's scope, so that what fits does not depend on the machine.
class ScopedBudget {
 public:
  explicit ScopedBudget(const char* megabytes) {
    if (const char* old = std::getenv("VOX_MEMORY_LIMIT_MB")) old_ = old;
    ::setenv("VOX_MEMORY_LIMIT_MB", megabytes, 1);
  }
  ~ScopedBudget() {
    if (old_)
      ::setenv("VOX_MEMORY_LIMIT_MB", old_->c_str(), 1);
    else
      ::unsetenv("VOX_MEMORY_LIMIT_MB");
  }

 private:
  std::optional<std::string> old_;
};

// The message of the LimitError that `f` throws (failing the test when it throws nothing or something else), and
// that it threw within `seconds`: a refusal comes from the runs' counts, before any row is visited.
template <typename F>
std::string limitMessage(F&& f, double seconds = 2.0) {
  const auto start = std::chrono::steady_clock::now();
  std::string message = "(nothing thrown)";
  try {
    f();
  } catch (const LimitError& e) {
    message = e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a LimitError: " << e.what();
    return e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), seconds) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  return message;
}

TEST(VoxelRuns, TallyCountsVoxelsAndRowsFromTheRunsAlone) {
  for (const auto& dims : {std::array<uint32_t, 3>{37, 11, 9}, {5, 70, 23}, {1, 1, 1}, {130, 3, 129}}) {
    Grid g = randomGrid(dims, dims[1], 200, 30);
    g.solidRuns.push_back({g.cellCount() - 1, 1});  // the last cell, so that a run ends at the grid's end
    if (g.solidRuns.size() > 1) {
      const CellRun& prev = g.solidRuns[g.solidRuns.size() - 2];
      if (prev.first + prev.count >= g.cellCount() - 1) g.solidRuns.pop_back();
    }
    uint64_t voxels = 0, rows = 0;
    forEachVoxelRow(g, [&](const VoxelRow& r) {
      voxels += r.count;
      ++rows;
    });
    const VoxelTally t = tallyVoxels(g);
    EXPECT_EQ(t.voxels, voxels);
    EXPECT_EQ(t.rows, rows);
    EXPECT_EQ(t.voxels, voxelSet(g).size());
  }
  // 2^63 cells in one run: 2^42 rows, counted without visiting one.
  const auto start = std::chrono::steady_clock::now();
  const VoxelTally t = tallyVoxels(oneRunGrid(1u << 21));
  EXPECT_EQ(t.voxels, uint64_t(1) << 63);
  EXPECT_EQ(t.rows, uint64_t(1) << 42);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.5);
  Grid tooLarge = oneRunGrid(1);
  tooLarge.dims = {1u << 22, 1, 1};  // past 2^21 on an axis: keys could reach 2^64
  EXPECT_THROW(tallyVoxels(tooLarge), InputError);
}

// Cells of 1e-120 a side are a valid grid, but their volume underflows to 0 and OpenVDB's transform threw its own
// exception through writeVdb (fuzz_voxel_writers, tests/data/fuzz/voxel_writers/vdb-zero-scale-394f3b71.bin).
TEST(Vdb, CellsTooSmallForOpenVdbsTransformAreRefusedNamingTheirSides) {
  Grid g = randomGrid({4, 4, 4}, 3, 10, 2);
  g.bounds = {{0, 0, 0}, {4e-120, 4e-120, 4e-120}};
  std::ostringstream out;
  EXPECT_NE(limitMessage([&] { writeVdb(out, g); }).find("vdb: cells of 1e-120 x 1e-120 x 1e-120 are beyond OpenVDB"),
            std::string::npos);
  g.bounds = {{0, 0, 0}, {4e200, 4e200, 4e200}};  // a volume of 1e600 overflows
  EXPECT_NE(limitMessage([&] { writeVdb(out, g); }).find("vdb: cells of 1e+200 x"), std::string::npos);
  g.bounds = {{0, 0, 0}, {4, 4, 4}};
  EXPECT_NO_THROW(writeVdb(out, g));
}

// The 906-byte grid of issue 23 (dims 2^21, no occupied cell, one run over all 2^63 cells): .vox ran past 40 s
// with memory growing 3 MB/s, .vdb past 40 s, the meshes said "vector::reserve" (the estimate (occupied + solid) * 12
// wrapped to 0).
TEST(HostileSolidRuns, TwoTo63SolidCellsAreRefusedAtOnceByEveryWriter) {
  ScopedBudget budget("1024");
  const Grid g = oneRunGrid(1u << 21);
  std::ostringstream out;
  EXPECT_NE(limitMessage([&] { writeBinvox(out, g); }).find("binvox: the grid's 2097152 cells"), std::string::npos);
  EXPECT_NE(limitMessage([&] {
              writeMagicaVoxel(out, g, {}, kSolidCellColor);
            }).find("vox: 9223372036854775808 (2^63) voxels need 2^64 bytes or more"),
            std::string::npos);
  EXPECT_NE(limitMessage([&] { writeVdb(out, g); }).find("vdb: the voxels need 134217728 root tiles"),
            std::string::npos);
  for (FaceMode faces : {FaceMode::Exposed, FaceMode::Merged, FaceMode::All})
    EXPECT_NE(limitMessage([&] {
                buildVoxelMesh(g, Scene{}, faces, ColorMode::Count);
              }).find("voxel mesh: a list of 9223372036854775808 (2^63) voxels at "),
              std::string::npos);
  EXPECT_TRUE(out.str().empty());
}

// 16384^3 in one run (2^42 cells): .vox took over 40 s (one row at a time). .vdb is 64 root tiles and no leaf.
TEST(HostileSolidRuns, TwoTo42SolidCellsAreOneQuickVdbAndRefusedElsewhere) {
  ScopedBudget budget("1024");
  const Grid g = oneRunGrid(16384);
  std::ostringstream out;
  EXPECT_NE(limitMessage([&] { writeMagicaVoxel(out, g, {}, kSolidCellColor); })
                .find("vox: 4398046511104 (2^42) voxels need at least 17592186044416 (2^44) bytes, more than the "
                      "2^31 - 1"),
            std::string::npos);
  EXPECT_NE(limitMessage([&] {
              buildVoxelMesh(g, Scene{}, FaceMode::Exposed, ColorMode::None);
            }).find("4398046511104 (2^42) voxels"),
            std::string::npos);
  EXPECT_NE(limitMessage([&] { writeBinvox(out, g); }).find("16384 cells on its longest axis"), std::string::npos);
  EXPECT_TRUE(out.str().empty());
  const auto start = std::chrono::steady_clock::now();
  const VdbStats s = writeVdb(out, g);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  EXPECT_EQ(s.activeVoxels, uint64_t(1) << 42);
  EXPECT_EQ(s.leafNodes, 0u);
  std::istringstream in(out.str());
  openvdb::initialize();
  openvdb::io::Stream stream(in);
  auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(openvdb::findGridByName(*stream.getGrids(), "density"));
  ASSERT_TRUE(density);
  EXPECT_EQ(density->activeVoxelCount(), uint64_t(1) << 42);
  EXPECT_EQ(density->tree().root().getTableSize(), 64u);  // 4^3 tiles of 4096^3
  EXPECT_EQ(density->evalActiveVoxelBoundingBox(), openvdb::CoordBBox({0, 0, 0}, {16383, 16383, 16383}));
}

// All 1024^3 cells solid: the meshes took 14.6 GB and a minute before the budget refused them; now the voxel list's
// estimate (32 bytes a voxel for the exposed surface) refuses them before anything is allocated. binvox and .vdb
// answer quickly; .vox refuses (4 GiB of XYZI).
TEST(HostileSolidRuns, AllSolid1024CubedIsRefusedByTheMeshesBeforeAllocating) {
  ScopedBudget budget("1024");
  const Grid g = oneRunGrid(1024);
  for (FaceMode faces : {FaceMode::Exposed, FaceMode::Merged, FaceMode::All}) {
    const std::string m = limitMessage([&] { buildVoxelMesh(g, Scene{}, faces, ColorMode::Count); });
    EXPECT_NE(m.find("voxel mesh: a list of 1073741824 voxels at "), std::string::npos) << m;
    EXPECT_NE(m.find("MiB, more than the 1024 MiB allowed"), std::string::npos) << m;
  }
  std::ostringstream vox;
  EXPECT_NE(limitMessage([&] {
              writeMagicaVoxel(vox, g, {}, kSolidCellColor);
            }).find("vox: 1073741824 voxels need at least 4294967296 (2^32) bytes"),
            std::string::npos);
  std::ostringstream vdb;
  const VdbStats s = writeVdb(vdb, g);
  EXPECT_EQ(s.activeVoxels, uint64_t(1) << 30);
  EXPECT_EQ(s.leafNodes, 0u);
  // binvox: 2^30 set bits as pairs (1, 255) and a last (1, 2^30 mod 255).
  std::ostringstream binvox;
  writeBinvox(binvox, g);
  const std::string bytes = binvox.str();
  const size_t data = bytes.find("data\n") + 5;
  const uint64_t pairs = ((uint64_t(1) << 30) + 254) / 255;
  ASSERT_EQ(bytes.size() - data, 2 * pairs);
  for (size_t p = 0; p < pairs; ++p) {
    ASSERT_EQ(bytes[data + 2 * p], 1);
    ASSERT_EQ(uint8_t(bytes[data + 2 * p + 1]), p + 1 < pairs ? 255 : (uint64_t(1) << 30) % 255);
  }
}

// The estimates that once wrapped: (occupied + solid) * 12 for 2^63 solid cells is 0 mod 2^64, so the check passed
// and reserve(2^63) threw std::length_error "vector::reserve"; no writer lets such an error out.
TEST(HostileSolidRuns, NoEstimateWrapsPastTheBudget) {
  ScopedBudget budget("64");
  Grid g = oneRunGrid(1u << 21);
  g.solidRuns = {{0, (uint64_t(1) << 62) + (uint64_t(1) << 61)}, {uint64_t(7) << 60, uint64_t(1) << 60}};
  g.cellKeys = {(uint64_t(1) << 62) + (uint64_t(1) << 61) + 5};
  g.primIds = {0};
  g.cellStart = {0, 1};
  for (FaceMode faces : {FaceMode::Exposed, FaceMode::All})
    EXPECT_NE(limitMessage([&] { buildVoxelMesh(g, Scene{}, faces, ColorMode::Count); }).find("voxel mesh: "),
              std::string::npos);
  std::ostringstream out;
  limitMessage([&] { writeMagicaVoxel(out, g, {}, kSolidCellColor); });
  limitMessage([&] { writeVdb(out, g); });
}

// Rows of solid cells one row apart: four exposed squares a voxel, so the squares (counted while the vertices are
// numbered) are refused where the voxel list's estimate of 32 bytes a voxel still fits.
TEST(HostileSolidRuns, SquaresOfSolidRowsAreCountedBeforeTheyAreMade) {
  ScopedBudget budget("100");
  Grid g = oneRunGrid(1024);
  g.dims[2] = 2;
  g.solidRuns.clear();
  for (uint64_t j = 0; j < 1024; j += 2) g.solidRuns.push_back({j * 1024, 1024});
  const std::string m = limitMessage([&] { buildVoxelMesh(g, Scene{}, FaceMode::Exposed, ColorMode::None); }, 5.0);
  EXPECT_NE(m.find("voxel mesh: 2098176 exposed squares needs about"), std::string::npos) << m;
  // Half as many rows fit, and their mesh has exactly those squares.
  g.solidRuns.resize(128);
  VoxelMeshStats stats;
  const VoxelMesh mesh = buildVoxelMesh(g, Scene{}, FaceMode::Exposed, ColorMode::None, &stats);
  EXPECT_EQ(stats.exposedFaces, 128u * (4 * 1024 + 2));
  EXPECT_EQ(mesh.faceCount(), stats.exposedFaces);
}

// The same grid as a set of two bricks (z halves, each one run of 2^62 cells): binvox and .vox read it one layer of
// bricks at a time (writeGridSetVoxelFile), and refuse it from the first layer's runs; .vdb and the meshes get the
// assembled set, two runs, and refuse it as the single grid.
TEST(HostileSolidRuns, TwoTo63SolidCellsInAGridSetAreRefusedAtOnce) {
  ScopedBudget budget("1024");
  testing::ScratchDir dir("hostile_set");
  const std::string path = dir.file("s.vgrid");
  const Grid whole = oneRunGrid(1u << 21);
  Grid plan = whole;
  plan.solidRuns.clear();
  GridSetManifest m;
  m.bounds = plan.bounds;
  m.dims = plan.dims;
  m.method = plan.method;
  m.bricks = {1, 1, 2};
  {
    GridSetOutput output(path);
    m.scene = writeGridSetScene(path, output.folder(), Scene{}, plan);
    for (uint32_t bz = 0; bz < 2; ++bz) {
      Grid cells = plan;
      cells.solidRuns = {{uint64_t(bz) << 62, uint64_t(1) << 62}};
      m.entries.push_back(writeBrickFile(path, m, {0, 0, bz}, cells));
    }
    output.commit(m);
  }
  const GridSetManifest read = readGridSetManifest(path);
  const GridFile sceneFile = readGridSetScene(path, read);
  EXPECT_NE(limitMessage([&] {
              writeGridSetVoxelFile(dir.file("s.binvox"), VoxelFormat::Binvox, path, read, sceneFile, ColorMode::Count);
            }).find("binvox: the grid's 2097152 cells"),
            std::string::npos);
  for (ColorMode color : {ColorMode::Count, ColorMode::None})
    EXPECT_NE(limitMessage([&] {
                writeGridSetVoxelFile(dir.file("s.vox"), VoxelFormat::MagicaVoxel, path, read, sceneFile, color);
              }).find("vox: 4611686018427387904 (2^62) voxels need 2^64 bytes or more"),
              std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.file("s.vox")));
  const GridFile set = readGridOrSet(path);
  EXPECT_EQ(tallyVoxels(set.grid).voxels, uint64_t(1) << 63);
  EXPECT_NE(limitMessage([&] {
              writeVoxelFile(dir.file("s.vdb"), VoxelFormat::Vdb, set.grid, {});
            }).find("134217728 root tiles"),
            std::string::npos);
  EXPECT_NE(limitMessage([&] {
              buildVoxelMesh(set.grid, set.scene, FaceMode::Exposed, ColorMode::Count);
            }).find("(2^63) voxels"),
            std::string::npos);
}

// Runs that cross rows and planes, in grids thin and thick: the .vdb builder takes whole rows as rectangles and
// whole planes as boxes; the voxels read back by OpenVDB must be exactly the grid's.
TEST(Vdb, RunsAcrossRowsAndPlanesKeepTheExactVoxels) {
  std::mt19937_64 rng(23);
  for (const auto& dims : {std::array<uint32_t, 3>{5, 4, 6}, {9, 17, 3}, {1, 7, 20}, {20, 1, 9}, {33, 9, 18}}) {
    for (int trial = 0; trial < 6; ++trial) {
      Grid g;
      g.dims = dims;
      g.bounds = {{0, 0, 0}, {1, 2, 3}};
      const uint64_t cells = g.cellCount();
      std::set<uint64_t> keys;
      for (int i = 0; i < 10; ++i) keys.insert(rng() % cells);
      g.cellKeys.assign(keys.begin(), keys.end());
      for (size_t c = 0; c < g.cellKeys.size(); ++c) {
        g.primIds.push_back(0);
        g.cellStart.push_back(g.primIds.size());
      }
      for (uint64_t at = rng() % (dims[0] + 1); at < cells;) {
        const uint64_t n = 1 + rng() % (trial % 2 ? cells : 2 * uint64_t(dims[0]) * dims[1]);
        g.solidRuns.push_back({at, std::min(n, cells - at)});
        at += n + 1 + rng() % (2 * dims[0]);
      }
      SCOPED_TRACE(::testing::Message() << dims[0] << "x" << dims[1] << "x" << dims[2] << " trial " << trial);
      std::ostringstream out;
      const VdbStats s = writeVdb(out, g);
      std::istringstream in(out.str());
      openvdb::initialize();
      openvdb::io::Stream stream(in);
      auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(openvdb::findGridByName(*stream.getGrids(), "density"));
      ASSERT_TRUE(density);
      const std::set<Cell> cells2 = voxelSet(g);
      EXPECT_EQ(s.activeVoxels, cells2.size());
      std::set<Cell> got;
      for (auto it = density->cbeginValueOn(); it; ++it) {
        const openvdb::CoordBBox box = it.getBoundingBox();
        for (auto c = box.begin(); c; ++c) got.insert({uint32_t((*c)[0]), uint32_t((*c)[1]), uint32_t((*c)[2])});
      }
      EXPECT_EQ(got, cells2);
    }
  }
}

// The .vdb builder's estimate counts the nodes a fill makes; a thin plane over a wide grid is refused before it is
// filled (2^36 leaves), while the same cells as whole planes are tiles.
TEST(Vdb, AThinWidePlaneIsRefusedBeforeItsLeavesAreMade) {
  ScopedBudget budget("256");
  Grid g = oneRunGrid(1u << 21);
  g.solidRuns = {{1, (uint64_t(1) << 42) - 1}};  // plane k = 0 but for its first cell
  std::ostringstream out;
  EXPECT_NE(limitMessage([&] { writeVdb(out, g); }).find("vdb: the OpenVDB trees of the voxels need at least"),
            std::string::npos);
}

// The fuzz target's inputs (tests/data/fuzz/voxel_writers/: the crafted grids above as seeds, and what fuzzing
// saved) replay through its own code: each writer answers or refuses, never crashes, within the test's time.
TEST(FuzzVoxelWriters, SavedInputsAnswerOrAreRefused) {
  ScopedBudget budget(fuzz::kWriterBudgetMb);
  const std::filesystem::path folder = std::filesystem::path(VOX_SOURCE_DIR) / "tests/data/fuzz/voxel_writers";
  ASSERT_TRUE(std::filesystem::is_directory(folder)) << folder;
  int replayed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    SCOPED_TRACE(entry.path().string());
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes{std::istreambuf_iterator<char>(in), {}};
    EXPECT_NO_THROW(fuzz::runVoxelWritersInput(bytes));
    ++replayed;
  }
  EXPECT_GE(replayed, 4);
}

}  // namespace
}  // namespace vox
