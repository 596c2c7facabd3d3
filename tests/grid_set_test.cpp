// Grid sets on disk (io/grid_set.h): a set read back equals the single grid; manifests are untrusted input (every
// byte truncated or flipped is refused, brick names may not leave the manifest's folder, bricks must be the ones
// listed).
#include "vox/io/grid_set.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/io/atomic_file.h"
#include "vox/io/input_file.h"

namespace vox {
namespace {

std::string slurp(const std::string& path) { return readInputFile(path, "test file"); }

void expectSameGrid(const Grid& a, const Grid& b) {
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.cellKeys, b.cellKeys);
  EXPECT_EQ(a.cellStart, b.cellStart);
  EXPECT_EQ(a.primIds, b.primIds);
  EXPECT_EQ(a.outsidePrims, b.outsidePrims);
}

Scene sceneWithPlane(uint32_t seed) {
  Scene s = testing::randomScene(seed, 30, 3, -1, 2);
  s.planes.push_back({{0, 1, 0}, 0.1, 0});
  return s;
}

TEST(GridSet, ReadBackEqualsTheSingleGridAndItsFile) {
  testing::ScratchDir dir("gridset");
  const Scene scene = sceneWithPlane(7);
  for (const auto bricks : {std::array<uint32_t, 3>{1, 1, 1}, {7, 5, 3}, {10, 1, 1}, {2, 1, 4}}) {
    VoxelizeOptions o;
    o.dims = std::array<uint32_t, 3>{10, 9, 8};
    o.bounds = Box{{-0.8, -0.9, -0.7}, {0.9, 0.8, 0.75}};  // some primitives stick out
    const Grid single = voxelizeScene(scene, o);
    ASSERT_FALSE(single.outsidePrims.empty());
    const std::string path = dir.file("s.vgrid");
    const GridSetManifest m = writeGridSet(path, scene, o, bricks);
    EXPECT_GT(m.entries.size(), 0u);
    EXPECT_TRUE(isGridSet(path));
    const GridFile set = readGridOrSet(path);
    expectSameGrid(set.grid, single);
    // The scene comes back whole, so the set re-encodes to exactly the single grid's file.
    EXPECT_EQ(encodeGridFile(set.scene, set.grid), encodeGridFile(scene, single));
  }
  writeGridFile(dir.file("g.vgrid"), scene, voxelizeScene(scene, {}));
  EXPECT_FALSE(isGridSet(dir.file("g.vgrid")));
  EXPECT_EQ(readGridOrSet(dir.file("g.vgrid")).grid.cellKeys, voxelizeScene(scene, {}).cellKeys);
}

TEST(GridSet, EveryTruncationAndBitFlipOfTheManifestIsRefused) {
  testing::ScratchDir dir("gridset_bits");
  const std::string path = dir.file("s.vgrid");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  writeGridSet(path, sceneWithPlane(3), o, {3, 2, 2});
  const std::string bytes = slurp(path);
  for (size_t n = 0; n < bytes.size(); ++n) EXPECT_THROW(decodeGridSetManifest(bytes.substr(0, n), "m"), InputError);
  for (size_t bit = 0; bit < bytes.size() * 8; ++bit) {
    std::string b = bytes;
    b[bit / 8] = char(b[bit / 8] ^ (1 << (bit % 8)));
    EXPECT_THROW(decodeGridSetManifest(b, "m"), InputError) << "bit " << bit;
  }
  EXPECT_NO_THROW(decodeGridSetManifest(bytes, "m"));
}

// A manifest written by hand (valid checksum) that lies about its bricks.
TEST(GridSet, ManifestsThatLieAreRefused) {
  testing::ScratchDir dir("gridset_lies");
  const std::string path = dir.file("s.vgrid");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  const GridSetManifest good = writeGridSet(path, sceneWithPlane(5), o, {2, 2, 1});
  ASSERT_GE(good.entries.size(), 2u);
  auto refused = [&](GridSetManifest m, const std::string& what) {
    writeFileAtomically(dir.file("lie.vgrid"), encodeGridSetManifest(m));
    try {
      readGridSet(dir.file("lie.vgrid"));
      ADD_FAILURE() << "accepted: " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  GridSetManifest m = good;
  m.entries[0].file = "../" + m.entries[0].file;
  refused(m, "outside");
  m = good;
  m.entries[0].file = "/etc/passwd";
  refused(m, "absolute");
  m = good;
  std::swap(m.entries[0].file, m.entries[1].file);  // each brick file under the other's index
  refused(m, "not the brick");
  m = good;
  m.entries[1] = m.entries[0];  // the same brick twice
  refused(m, "ascending");
  m = good;
  m.entries[0].index[0] = 5;
  refused(m, "out of range");
  m = good;
  m.dims[0] = 7;
  refused(m, "differ from its manifest");
  m = good;
  m.entries[0].fileChecksum ^= 1;
  refused(m, "not the brick");
  m = good;
  m.entries.clear();
  refused(m, "at least one brick");
  // A brick moved to another brick's index: the cells are outside it.
  m = good;
  const auto moved = m.entries[1].index;
  m.entries[1].index = m.entries[0].index;
  m.entries[0].index = moved;
  std::swap(m.entries[0], m.entries[1]);
  refused(m, "outside its brick");
}

TEST(GridSet, NoManifestWhenABrickCannotBeWritten) {
  testing::ScratchDir dir("gridset_fail");
  const std::string path = dir.file("s.vgrid");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  std::filesystem::create_directories(dir.file("s.bricks/b_1_0_0.vgrid"));  // a folder where a brick goes
  EXPECT_THROW(writeGridSet(path, sceneWithPlane(5), o, {2, 1, 1}), OutputError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace vox
