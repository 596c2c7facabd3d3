// Grid files: exact round trip; truncation at every byte and every single-bit flip refused with InputError.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

#include "test_util.h"
#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/trace/render.h"
#include "vox/export/voxel_mesh.h"
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
  // A file whose checksum is right but whose cell table lies: written by a buggy or hostile writer.
  const Scene scene = sampleScene();
  VoxelizeOptions opt;
  opt.dims = {3, 3, 3};
  Grid grid = voxelizeScene(scene, opt);
  Grid badKeys = grid;
  std::swap(badKeys.cellKeys[0], badKeys.cellKeys[1]);
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, badKeys), "x"), InputError);
  Grid badIds = grid;
  badIds.primIds[0] = 1000;
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, badIds), "x"), InputError);
  Grid badStart = grid;
  badStart.cellStart.back() += 1;
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, badStart), "x"), InputError);
  // Issue 9: offsets that run backwards ([0, 1, 0] with no references) crashed every tool: the primitive range of
  // cell 0 was walked before the offsets were checked.
  Grid backwards = grid;
  backwards.cellKeys = {0, 1};
  backwards.cellStart = {0, 1, 0};
  backwards.primIds.clear();
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, backwards), "x"), InputError);
  Grid pastEnd = grid;
  pastEnd.cellKeys = {0, 1};
  pastEnd.cellStart = {0, 5, 1};
  pastEnd.primIds = {0};
  EXPECT_THROW(decodeGridFile(encodeGridFile(scene, pastEnd), "x"), InputError);
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
  const std::string bytes = encodeGridFile(scene, voxelizeScene(scene, opt));
  std::mt19937 rng(17);
  int refused = 0, accepted = 0;
  for (int n = 0; n < 20000; ++n) {
    std::string m = bytes;
    const int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const size_t at = 32 + rng() % (m.size() - 32);
      switch (rng() % 3) {
        case 0: m[at] = char(rng()); break;
        case 1: m[at] = char(0xff); break;  // large counts and ids
        default: std::memset(&m[at], 0, std::min<size_t>(8, m.size() - at)); break;
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
