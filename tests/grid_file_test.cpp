// Grid files: exact round trip; truncation at every byte and every single-bit flip refused with InputError.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "io/byte_codec.h"
#include "test_util.h"
#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/trace/render.h"
#include "vox/export/voxel_mesh.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/voxelize.h"

#include "../fuzz/fuzz_entry.h"

namespace vox {
namespace {

Scene sampleScene() {
  Scene scene = testing::randomScene(21, 6, 2);
  scene.materials.push_back({"red", {1, 0, 0}, {1, 1, 1}, 32, {}, {}, 1.5});
  scene.triangles[1].material = 1;
  scene.planes.push_back({{0, 1, 0}, -0.5, 1});
  scene.camera = Camera{CameraKind::Orthographic, {0, 0, 5}, {0, 0, -1}, {0, 1, 0}, 30, 3};
  scene.lights.push_back({LightKind::Point, {0, -1, 0}, {1, 2, 3}, {0.5, 0.5, 0.5}, {1, 0, 0.1}});
  scene.background = {0.1, 0.2, 0.3};
  scene.ambient = {0.05, 0.05, 0.05};
  return scene;
}

bool sameVec(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

TEST(GridFile, RoundTripsEverything) {
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {5, 4, 3};
  opt.bounds = Box{{0.1, 0.1, 0.1}, {0.9, 0.9, 0.9}};
  const Grid grid = voxelizeScene(scene, opt);
  ASSERT_GT(grid.occupiedCount(), 0u);
  testing::ScratchDir dir("gridfile");
  const std::string path = dir.file("a.vgrid");
  writeGridFile(path, scene, grid);
  const GridFile back = readGridFile(path);
  ASSERT_EQ(back.scene.triangles.size(), scene.triangles.size());
  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(sameVec(back.scene.triangles[i].v[k], scene.triangles[i].v[k]));
    EXPECT_EQ(back.scene.triangles[i].material, scene.triangles[i].material);
  }
  ASSERT_EQ(back.scene.spheres.size(), scene.spheres.size());
  for (size_t i = 0; i < scene.spheres.size(); ++i) {
    EXPECT_TRUE(sameVec(back.scene.spheres[i].center, scene.spheres[i].center));
    EXPECT_EQ(back.scene.spheres[i].radius, scene.spheres[i].radius);
    EXPECT_EQ(back.scene.spheres[i].transform.m, scene.spheres[i].transform.m);
  }
  ASSERT_EQ(back.scene.planes.size(), 1u);
  EXPECT_EQ(back.scene.planes[0].offset, -0.5);
  ASSERT_EQ(back.scene.materials.size(), 2u);
  EXPECT_EQ(back.scene.materials[1].name, "red");
  EXPECT_EQ(back.scene.materials[1].exponent, 32);
  ASSERT_TRUE(back.scene.camera);
  EXPECT_EQ(back.scene.camera->kind, CameraKind::Orthographic);
  EXPECT_EQ(back.scene.camera->orthoHeight, 3);
  ASSERT_EQ(back.scene.lights.size(), 1u);
  EXPECT_TRUE(sameVec(back.scene.lights[0].attenuation, {1, 0, 0.1}));
  EXPECT_TRUE(sameVec(back.scene.background, scene.background));
  EXPECT_EQ(back.grid.dims, grid.dims);
  EXPECT_TRUE(sameVec(back.grid.bounds.lo, grid.bounds.lo));
  EXPECT_EQ(back.grid.method, grid.method);
  EXPECT_EQ(back.grid.cellKeys, grid.cellKeys);
  EXPECT_EQ(back.grid.cellStart, grid.cellStart);
  EXPECT_EQ(back.grid.primIds, grid.primIds);
  EXPECT_EQ(back.grid.outsidePrims, grid.outsidePrims);
  // Same bytes again: encoding is deterministic.
  EXPECT_EQ(encodeGridFile(back.scene, back.grid), encodeGridFile(scene, grid));
}

// A write cancelled at any of its progress calls (Ctrl-C in Python's save) throws, leaves the old output byte for
// byte and no temporary file; progress runs from 0 to 1.
TEST(GridFile, CancelledWriteKeepsTheOldOutput) {
  const Scene scene = testing::boxScene(0, 1);
  VoxelizeOptions opt;
  opt.dims = {64, 64, 64};
  const Grid grid = voxelizeScene(scene, opt);
  testing::ScratchDir dir("gridfile_cancel");
  const std::string path = dir.file("a.vgrid");
  writeFileAtomically(path, "old bytes");
  int calls = 0;
  double last = 0;
  writeGridFile(dir.file("full.vgrid"), scene, grid, nullptr, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
    return ++calls > 0;
  });
  EXPECT_EQ(last, 1.0);
  ASSERT_GT(calls, 3);
  for (int stop : {1, 2, calls / 2, calls}) {
    int seen = 0;
    EXPECT_THROW(writeGridFile(path, scene, grid, nullptr, [&](double) { return ++seen < stop; }), Error) << stop;
    EXPECT_EQ(testing::readAll(path), "old bytes") << stop;
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 2);  // a.vgrid, full.vgrid
  // Reading and encoding (load, pickling) cancel the same way.
  EXPECT_THROW(readGridFile(dir.file("full.vgrid"), [](double) { return false; }), Error);
  EXPECT_THROW(encodeGridFile(scene, grid, 0, [](double) { return false; }), Error);
  int reads = 0;
  EXPECT_EQ(readGridFile(dir.file("full.vgrid"), [&](double) { return ++reads > 0; }).grid.cellKeys, grid.cellKeys);
  EXPECT_GT(reads, 0);
}

TEST(GridFile, EveryTruncationAndBitFlipIsRefused) {
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {3, 3, 3};
  const std::string bytes = encodeGridFile(scene, voxelizeScene(scene, opt));
  ASSERT_NO_THROW(decodeGridFile(bytes, "ok.vgrid"));
  for (size_t n = 0; n < bytes.size(); ++n) {
    try {
      decodeGridFile(bytes.substr(0, n), "cut.vgrid");
      FAIL() << "truncation at " << n << " accepted";
    } catch (const InputError& e) {
      ASSERT_NE(std::string(e.what()).find("cut.vgrid"), std::string::npos);
    }
  }
  for (size_t bit = 0; bit < bytes.size() * 8; ++bit) {
    std::string flipped = bytes;
    flipped[bit / 8] = char(flipped[bit / 8] ^ (1 << (bit % 8)));
    EXPECT_THROW(decodeGridFile(flipped, "flip.vgrid"), InputError) << "bit " << bit;
  }
}

TEST(GridFile, ParserChecksStructureEvenWithAValidChecksum) {
  // A file whose checksum is right but whose cell table lies: written by a buggy or hostile writer. Version 2's flat
  // arrays can carry every such lie (the version 3 table's own are in grid_cell_table_test.cpp; its encoder takes
  // only well-formed grids, and unsorted keys or a bad id are the lies it can be made to write).
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {3, 3, 3};
  Grid grid = voxelizeScene(scene, opt);
  Grid badKeys = grid;
  std::swap(badKeys.cellKeys[0], badKeys.cellKeys[1]);
  Grid badIds = grid;
  badIds.primIds[0] = 1000;
  for (const uint32_t version : {2u, 3u}) {
    EXPECT_THROW(decodeGridFile(encodeGridFile(scene, badKeys, version), "x"), InputError) << version;
    EXPECT_THROW(decodeGridFile(encodeGridFile(scene, badIds, version), "x"), InputError) << version;
  }
  Grid badStart = grid;
  badStart.cellStart.back() += 1;
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, badStart, 2), "x"), InputError);
  // Issue 9: offsets that run backwards ([0, 1, 0] with no references) crashed every tool: the primitive range of
  // cell 0 was walked before the offsets were checked.
  Grid backwards = grid;
  backwards.cellKeys = {0, 1};
  backwards.cellStart = {0, 1, 0};
  backwards.primIds.clear();
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, backwards, 2), "x"), InputError);
  Grid pastEnd = grid;
  pastEnd.cellKeys = {0, 1};
  pastEnd.cellStart = {0, 5, 1};
  pastEnd.primIds = {0};
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, pastEnd, 2), "x"), InputError);
  // A camera that cannot form an image and a singular ellipsoid are the file's fault (exit 2, named), not usage
  // errors found later while tracing.
  Scene zeroCamera = scene;
  zeroCamera.camera = Camera{};
  zeroCamera.camera->direction = {0, 0, 0};
  try {
    decodeGridFile(encodeGridFile(zeroCamera, grid), "cam.vgrid");
    FAIL() << "zero camera direction accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cam.vgrid: camera direction is zero"), std::string::npos) << e.what();
  }
  Scene parallelUp = scene;
  parallelUp.camera = Camera{};
  parallelUp.camera->up = {0, 0, -2};
  EXPECT_THROW(decodeGridFile(encodeGridFile(parallelUp, grid), "x"), InputError);
  Scene singular = scene;
  Sphere flat;
  flat.transform = scaling({1, 0, 1});
  singular.spheres.push_back(flat);
  EXPECT_THROW(decodeGridFile(encodeGridFile(singular, grid), "x"), InputError);
  Scene badMaterial = scene;
  badMaterial.triangles[0].material = 9;
  EXPECT_THROW(decodeGridFile(encodeGridFile(badMaterial, grid), "x"), InputError);
}

// Rebuilds `v2` (a version 2 encoding whose grid has no solid runs and no sections) as the version 1 file that
// stored `solidKeys` one key each: the same payload up to the solid cells, then array<u64> of keys.
std::string asVersion1(const std::string& v2, const std::vector<uint64_t>& solidKeys) {
  std::string bytes = v2.substr(0, v2.size() - 8);  // drop the empty run array's count
  const uint64_t n = solidKeys.size();
  bytes.append(reinterpret_cast<const char*>(&n), 8);
  bytes.append(reinterpret_cast<const char*>(solidKeys.data()), n * 8);
  const uint32_t version = 1;
  const uint64_t size = bytes.size() - 32, sum = gridChecksum(bytes.data() + 32, size);
  std::memcpy(bytes.data() + 8, &version, 4);
  std::memcpy(bytes.data() + 16, &size, 8);
  std::memcpy(bytes.data() + 24, &sum, 8);
  return bytes;
}

// Replaces the checksum of an edited encoding, so the parser's own checks face the edit.
std::string resum(std::string bytes) {
  const uint64_t size = bytes.size() - 32, sum = gridChecksum(bytes.data() + 32, size);
  std::memcpy(bytes.data() + 16, &size, 8);
  std::memcpy(bytes.data() + 24, &sum, 8);
  return bytes;
}

TEST(GridFile, SolidRunsRoundTripAndVersion1KeysStillRead) {
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {7, 5, 3};
  Grid grid = voxelizeScene(scene, opt);
  const std::string plain = encodeGridFile(scene, grid, 2);
  // Keys 3,4,5 and 9 and the last cell: runs {3,3}, {9,1}, {104,1}; one run crossing a row boundary (6, 7).
  const std::vector<uint64_t> keys = {3, 4, 5, 6, 7, 9, 104};
  for (uint64_t k : keys) appendSolidKey(grid.solidRuns, k);
  ASSERT_EQ(grid.solidRuns.size(), 3u);
  EXPECT_EQ(grid.solidRuns[0].first, 3u);
  EXPECT_EQ(grid.solidRuns[0].count, 5u);
  EXPECT_EQ(grid.solidCount(), 7u);
  for (uint64_t k = 0; k < grid.cellCount(); ++k)
    EXPECT_EQ(isSolid(grid, k), std::find(keys.begin(), keys.end(), k) != keys.end()) << k;
  const GridFile back = decodeGridFile(encodeGridFile(scene, grid), "runs.vgrid");
  ASSERT_EQ(back.grid.solidRuns.size(), grid.solidRuns.size());
  for (size_t r = 0; r < grid.solidRuns.size(); ++r) {
    EXPECT_EQ(back.grid.solidRuns[r].first, grid.solidRuns[r].first);
    EXPECT_EQ(back.grid.solidRuns[r].count, grid.solidRuns[r].count);
  }
  // The same grid written by version 1 (one key per solid cell) reads as the same runs.
  const GridFile old = decodeGridFile(asVersion1(plain, keys), "old.vgrid");
  ASSERT_EQ(old.grid.solidRuns.size(), 3u);
  EXPECT_EQ(old.grid.solidCount(), 7u);
  EXPECT_EQ(old.grid.cellKeys, grid.cellKeys);
  EXPECT_EQ(encodeGridFile(old.scene, old.grid), encodeGridFile(scene, grid));
  EXPECT_THROW(decodeGridFile(asVersion1(plain, {5, 4}), "old.vgrid"), InputError);
  EXPECT_THROW(decodeGridFile(asVersion1(plain, {105}), "old.vgrid"), InputError);
}

TEST(GridFile, BadSolidRunsAndUnknownSectionsAreRefused) {
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {4, 4, 4};
  const Grid grid = voxelizeScene(scene, opt);
  const std::vector<std::vector<CellRun>> bad = {
      {{0, 0}},            // empty run
      {{60, 5}},           // past the last cell
      {{10, 2}, {12, 1}},  // adjacent: must have been one run
      {{10, 3}, {11, 1}},  // overlapping
      {{20, 1}, {10, 1}},  // unsorted
      {{UINT64_MAX, 2}},   // wraps around
  };
  for (const auto& runs : bad) {
    Grid g = grid;
    g.solidRuns = runs;
    try {
      decodeGridFile(encodeGridFile(scene, g), "runs.vgrid");
      FAIL() << "bad runs accepted: first " << runs[0].first;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("runs.vgrid: solid runs at byte"), std::string::npos) << e.what();
    }
  }
  // A section this build does not know (a newer writer's) is refused by name, not skipped or misread.
  std::string bytes = encodeGridFile(scene, grid);
  const uint32_t tag = 999;
  const uint64_t size = 4;
  bytes.append(reinterpret_cast<const char*>(&tag), 4);
  bytes.append(reinterpret_cast<const char*>(&size), 8);
  bytes.append("abcd");
  try {
    decodeGridFile(resum(bytes), "tag.vgrid");
    FAIL() << "unknown section accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown section tag 999"), std::string::npos) << e.what();
  }
  // A section header promising more bytes than remain.
  bytes.resize(bytes.size() - 2);
  EXPECT_THROW(decodeGridFile(resum(bytes), "tag.vgrid"), InputError);
}

// Issue 45, defects 13 and 14: the Distances and Fractions sections of a grid that has both. A file holding them out
// of order (Fractions, tag 6, before Distances, tag 5) is refused, and values out of range are printed as they are
// (not -1e-300 as "-0.000000", nor the next double above 64 as "64" beside the limit 64), with the range.
TEST(GridFile, SectionsOutOfOrderAndBadBandOrFractionValuesAreRefusedExactly) {
  const Scene scene = testing::boxScene(0.2, 0.8);
  VoxelizeOptions opt;
  opt.dims = {4, 4, 4};
  Grid grid = voxelizeScene(scene, opt);
  grid.sdfHalfWidth = 2;
  grid.sdfKeys = {grid.cellKeys[0], grid.cellKeys[1]};
  grid.sdfValues = {0.125, -0.25};
  grid.fractions.assign(grid.occupiedCount(), 0.5);
  const std::string good = encodeGridFile(scene, grid);
  ASSERT_NO_THROW(decodeGridFile(good, "ok.vgrid"));
  Grid noBand = grid;
  noBand.sdfHalfWidth = 0;
  noBand.sdfKeys.clear();
  noBand.sdfValues.clear();
  // The Distances section's size: its keys are runs of varints (version 5), whose bytes depend on the keys.
  const size_t fractionsBytes = 12 + 8 + 8 * grid.occupiedCount(),
               distancesBytes = good.size() - encodeGridFile(scene, noBand).size();
  const size_t distancesAt = good.size() - fractionsBytes - distancesBytes;
  std::string swapped = good.substr(0, distancesAt) + good.substr(good.size() - fractionsBytes) +
                        good.substr(distancesAt, distancesBytes);
  ASSERT_EQ(swapped.size(), good.size());
  auto refusal = [](const std::string& bytes) {
    try {
      decodeGridFile(resum(bytes), "g.vgrid");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal(swapped).find("distances section (tag 5) after the fractions section (tag 6)"), std::string::npos)
      << refusal(swapped);
  const struct {
    double halfWidth, fraction;
    const char* message;
  } cases[] = {
      {2, -1e-300, "volume fraction -1e-300 outside [0, 1]"},
      {2, 1.0000000000000002, "volume fraction 1.0000000000000002 outside [0, 1]"},
      {std::nextafter(64.0, 65.0), 0.5, "distance band half-width 64.00000000000001 outside (0, 64] cell edges"},
      {-0.0, 0.5, "distance band half-width -0 outside (0, 64] cell edges"},
      {5e-324, 0.5, ""},  // the smallest positive double is a valid half-width
  };
  for (const auto& c : cases) {
    Grid g = grid;
    g.sdfHalfWidth = c.halfWidth;
    g.fractions.back() = c.fraction;
    std::string bytes = encodeGridFile(scene, g);
    if (c.halfWidth == 0) {  // a zero half-width writes no Distances section: put -0 into the file's own
      bytes = good;
      std::memcpy(&bytes[distancesAt + 12], &c.halfWidth, 8);
    }
    const std::string got = refusal(bytes);
    if (*c.message == 0)
      EXPECT_EQ(got, "accepted");
    else
      EXPECT_NE(got.find(c.message), std::string::npos) << got;
  }
}

TEST(GridFile, WrittenFileEqualsTheEncodingAcrossChunks) {
  // writeGridFile streams the encoding three times (size, checksum, bytes) in chunks of ByteWriter::kChunkBytes
  // with large arrays handed over whole; the file must be exactly encodeGridFile's bytes. A grid of several chunks,
  // with solid runs and arrays straddling chunk boundaries at odd offsets.
  Scene scene = sampleScene();
  scene.materials[1].name = "odd length";  // shifts every later byte off the 8-byte word grid
  VoxelizeOptions opt;
  opt.dims = {61, 47, 33};
  Grid grid = voxelizeScene(scene, opt);
  for (uint64_t k = 5; k < grid.cellCount(); k += 3)
    if (findCell(grid, k) < 0) appendSolidKey(grid.solidRuns, k);  // a cell is occupied or solid, not both
  const std::string expected = encodeGridFile(scene, grid);
  ASSERT_GT(expected.size(), 3 * ByteWriter::kChunkBytes);
  testing::ScratchDir dir("gridstream");
  const std::string path = dir.file("s.vgrid");
  writeGridFile(path, scene, grid);
  std::ifstream in(path, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written.size(), expected.size());
  EXPECT_TRUE(written == expected);
  EXPECT_EQ(encodeGridFile(readGridFile(path).scene, readGridFile(path).grid), expected);
}

TEST(GridFile, NewerVersionAndMissingFile) {
  const Scene scene = sampleScene();
  std::string bytes = encodeGridFile(scene, voxelizeScene(scene, {}));
  bytes[8] = char(kGridFileVersion + 1);
  try {
    decodeGridFile(bytes, "new.vgrid");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos);
  }
  EXPECT_THROW(readGridFile("/nonexistent/dir/x.vgrid"), InputError);
  EXPECT_THROW(writeGridFile("/nonexistent/dir/x.vgrid", scene, {}), OutputError);
}

}  // namespace
}  // namespace vox

namespace vox {
namespace {

// Structure fuzzing: random byte edits with the checksum recomputed, so the parser's own checks (counts, offsets,
// ids, kinds, finiteness) face the corruption instead of the checksum. Every input must decode or throw
// InputError; under AddressSanitizer this also proves no out-of-bounds read.
TEST(GridFile, MutationsWithValidChecksumDecodeOrThrow) {
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {4, 3, 5};
  const Grid grid = voxelizeScene(scene, opt);
  const std::string v3 = encodeGridFile(scene, grid), v2 = encodeGridFile(scene, grid, 2);
  std::mt19937 rng(17);
  int refused = 0, accepted = 0;
  // The current version's cell table (varints), then version 2's flat arrays, which old files still have.
  for (int n = 0; n < 25000; ++n) {
    std::string m = n < 20000 ? v3 : v2;
    const int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = 32 + rng() % (m.size() - 32);
      switch (rng() % 3) {
        case 0:
          m[at] = char(rng());
          break;
        case 1:
          m[at] = char(0xff);
          break;  // large counts and ids
        default:
          std::memset(&m[at], 0, std::min<size_t>(8, m.size() - at));
          break;
      }
    }
    if (rng() % 8 == 0) m.resize(32 + rng() % (m.size() - 32));  // truncated, then re-sized in the header
    const uint64_t size = m.size() - 32;
    std::memcpy(&m[16], &size, 8);
    const uint64_t sum = gridChecksum(m.data() + 32, size);
    std::memcpy(&m[24], &sum, 8);
    try {
      const GridFile file = decodeGridFile(m, "fuzz.vgrid");
      // What decodes must also be safe to trace and export, exactly as the grid fuzz target checks it.
      if (++accepted <= 300) fuzz::exerciseDecodedGrid(file);
    } catch (const InputError& e) {
      ASSERT_NE(std::string(e.what()).find("fuzz.vgrid"), std::string::npos);
      ++refused;
    }
  }
  EXPECT_GT(refused, 1000);
  RecordProperty("accepted", accepted);
}

}  // namespace
}  // namespace vox
