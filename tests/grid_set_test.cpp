// Grid sets on disk (io/grid_set.h): a set read back equals the single grid; manifests are untrusted input (every
// byte truncated or flipped is refused, brick names may not leave the manifest's folder, bricks must be the ones
// listed).
#include "vox/io/grid_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <fstream>
#include <random>
#include <sstream>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/export/voxel_format.h"
#include "vox/io/atomic_file.h"
#include "vox/io/info.h"
#include "vox/io/input_file.h"
#include "vox/import/import.h"
#include "vox/sets/fill_set.h"
#include "vox/sets/voxelize_set.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/bricks.h"

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
  m.entries[0].file = m.entries[0].file + "/../../../../" + m.entries[0].file;  // out through the brick folders
  refused(m, "outside");
  m = good;
  m.scene.file = "../" + m.scene.file;
  refused(m, "outside");
  m = good;
  m.entries[0].file = "/etc/passwd";
  refused(m, "absolute");
  // A control byte in a name would split the one-line error that prints it (found by fuzz/fuzz_grid.cpp).
  m = good;
  m.entries[0].file = m.entries[0].file + "\nvox-info: ok";
  refused(m, "bad file name");
  m = good;
  m.scene.file = "s\x7f";
  refused(m, "bad scene file name");
  // Counts a brick file of the listed size cannot hold: refused before the whole grid's arrays are sized by them.
  m = good;
  m.entries[0].occupied = m.entries[0].references = uint64_t(1) << 40;
  refused(m, "larger than its file");
  m = good;
  m.entries[0].fileSize += 1;
  refused(m, "not the brick");
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
  m.scene.checksum ^= 1;
  refused(m, "not the scene file");
  // A brick moved to another brick's index: the cells are outside it.
  m = good;
  const auto moved = m.entries[1].index;
  m.entries[1].index = m.entries[0].index;
  m.entries[0].index = moved;
  std::swap(m.entries[0], m.entries[1]);
  refused(m, "holds another brick");
}

// Readers refuse names with control bytes, so the writer refuses to make them.
TEST(GridSet, NamesWithControlBytesAreNotWritten) {
  testing::ScratchDir dir("gridset_names");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  EXPECT_THROW(writeGridSet(dir.file("a\nb.vgrid"), sceneWithPlane(5), o, {2, 1, 1}), OutputError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("a\nb.bricks")));
}

// The files under the brick folders of a scratch folder, as "NAME.bricks/gHEX/FILE" (temporary files included).
std::vector<std::string> setFiles(const testing::ScratchDir& dir) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir.path()))
    if (!e.is_directory()) files.push_back(std::filesystem::relative(e.path(), dir.path()).string());
  std::sort(files.begin(), files.end());
  return files;
}

VoxelizeOptions optionsCancellingAfter(int calls) {
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{12, 10, 8};
  auto left = std::make_shared<int>(calls);
  o.progress = [left](double) { return --*left > 0; };
  return o;
}

TEST(GridSet, NoManifestWhenABrickCannotBeWritten) {
  testing::ScratchDir dir("gridset_fail");
  const std::string path = dir.file("s.vgrid");
  EXPECT_THROW(writeGridSet(path, sceneWithPlane(5), optionsCancellingAfter(3), {3, 2, 2}), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(setFiles(dir), std::vector<std::string>{});  // the new generation folder went with the failure
}

// Issue 23: a rerun that fails after writing bricks (here: cancelled at the third brick) leaves the old set whole
// and readable, and no file of its own; a rerun that succeeds replaces the set and removes the old set's files.
TEST(GridSet, AFailedRerunLeavesTheOldSetWholeAndASuccessfulOneReplacesIt) {
  testing::ScratchDir dir("gridset_rerun");
  const std::string path = dir.file("s.vgrid");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  const Scene first = sceneWithPlane(3), second = sceneWithPlane(4);
  writeGridSet(path, first, o, {3, 2, 2});
  const std::vector<std::string> before = setFiles(dir);
  const Grid old = readGridSet(path).grid;
  EXPECT_THROW(writeGridSet(path, second, optionsCancellingAfter(3), {3, 2, 2}), Error);
  EXPECT_EQ(setFiles(dir), before);
  expectSameGrid(readGridSet(path).grid, old);

  writeGridSet(path, second, o, {2, 1, 1});
  expectSameGrid(readGridSet(path).grid, voxelizeScene(second, o));
  for (const std::string& f : setFiles(dir))
    EXPECT_TRUE(std::find(before.begin(), before.end(), f) == before.end() || f == "s.vgrid") << f << " left over";
  // Exactly the new set's files: the manifest, the scene file and its bricks, in one generation folder.
  const GridSetManifest m = readGridSetManifest(path);
  EXPECT_EQ(setFiles(dir).size(), 2 + m.entries.size());
  EXPECT_EQ(std::filesystem::path(m.scene.file).parent_path().parent_path().string(), "s.bricks");
}

// Two outputs whose names share a stem (s.vgrid and s.other both put their bricks under s.bricks/) never share a
// file: writing, rewriting or failing one leaves the other readable.
TEST(GridSet, TwoOutputsInOneFolderNeverShareAFile) {
  testing::ScratchDir dir("gridset_two");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  const Scene a = sceneWithPlane(3), b = sceneWithPlane(4);
  writeGridSet(dir.file("s.vgrid"), a, o, {2, 2, 2});
  writeGridSet(dir.file("s.other"), b, o, {2, 2, 2});
  writeGridSet(dir.file("s.other"), b, o, {2, 1, 1});
  EXPECT_THROW(writeGridSet(dir.file("s.other"), b, optionsCancellingAfter(2), {2, 2, 2}), Error);
  expectSameGrid(readGridSet(dir.file("s.vgrid")).grid, voxelizeScene(a, o));
  expectSameGrid(readGridSet(dir.file("s.other")).grid, voxelizeScene(b, o));
}

// A grid file written over a set (no --bricks) replaces it whole: vox-voxelize removes the old set's files, and only
// files of the set layout that are the ones listed (size and checksum): a manifest cannot make it remove others.
TEST(GridSet, OnlyTheReplacedSetsOwnFilesAreRemoved) {
  testing::ScratchDir dir("gridset_remove");
  const std::string path = dir.file("s.vgrid");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  const GridSetManifest m = writeGridSet(path, sceneWithPlane(3), o, {2, 2, 1});
  ASSERT_GE(m.entries.size(), 2u);
  GridSetManifest lie = m;
  writeFileAtomically(dir.file("keep.txt"), "user data");
  lie.entries[0].file = "keep.txt";  // not a layout name
  lie.entries[1].fileChecksum ^= 1;  // a layout name, but not the file listed
  removeGridSetFiles(path, lie);
  EXPECT_TRUE(std::filesystem::exists(dir.file("keep.txt")));
  EXPECT_TRUE(std::filesystem::exists(dir.file(m.entries[1].file)));
  EXPECT_FALSE(std::filesystem::exists(dir.file(m.scene.file)));
  removeGridSetFiles(path, m);
  EXPECT_EQ(setFiles(dir), (std::vector<std::string>{"keep.txt", "s.vgrid"}));
}

// "-o foo.bricks --bricks ...": its brick folder would have the manifest's name. Refused before any file is made.
TEST(GridSet, AnOutputNamedLikeItsBrickFolderIsRefusedUpFront) {
  testing::ScratchDir dir("gridset_name");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  try {
    writeGridSet(dir.file("foo.bricks"), sceneWithPlane(3), o, {2, 2, 1});
    ADD_FAILURE() << "accepted";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("foo.bricks"), std::string::npos) << e.what();
  }
  EXPECT_EQ(setFiles(dir), std::vector<std::string>{});
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

// A set's scene file replaced by a large file is refused by its size before it is read (2 GiB, sparse: reading it
// whole took 11 s and 2.1 GB).
TEST(GridSet, ASceneFileOfTheWrongSizeIsRefusedBeforeItIsRead) {
  testing::ScratchDir dir("gridset_bigscene");
  const std::string path = dir.file("s.vgrid");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  const GridSetManifest m = writeGridSet(path, sceneWithPlane(3), o, {2, 2, 1});
  std::filesystem::resize_file(dir.file(m.scene.file), uint64_t(2) << 30);
  try {
    readGridSet(path);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.vgrid: not the scene file"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("size differs"), std::string::npos) << e.what();
  }
}

// A cell is occupied or solid, never both: a file whose solid run covers an occupied cell is refused (vox-info
// counted such a cell twice while the exports wrote it once).
TEST(GridSet, ASolidRunOverAnOccupiedCellIsRefused) {
  testing::ScratchDir dir("gridset_overlap");
  const Scene scene = sceneWithPlane(3);
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  Grid g = voxelizeScene(scene, o);
  ASSERT_GT(g.occupiedCount(), 0u);
  g.solidRuns = {{g.cellKeys[0], 1}};
  try {
    decodeGridFile(encodeGridFile(scene, g), "g.vgrid");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("covers the occupied cell"), std::string::npos) << e.what();
  }
  g.solidRuns = {{0, g.cellKeys[0]}};  // up to the cell: accepted when it is not cell 0
  if (g.cellKeys[0] > 0) {
    EXPECT_NO_THROW(decodeGridFile(encodeGridFile(scene, g), "g.vgrid"));
  }
  // The same in a brick of a set.
  const std::string path = dir.file("s.vgrid");
  const GridSetManifest m = writeGridSet(path, scene, o, {1, 1, 1});
  Grid brick = readBrick(path, m, 0, scene.boundedCount());
  brick.solidRuns = {{brick.cellKeys.back(), 1}};
  GridSetManifest lie = m;
  lie.entries[0] = writeBrickFile(path, m, m.entries[0].index, brick);
  writeFileAtomically(path, encodeGridSetManifest(lie));
  try {
    readGridSet(path);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("covers the occupied cell"), std::string::npos) << e.what();
  }
}

// --fill over a set gives the single grid's solid cells, run for run, for closed (flood) and open (winding number)
// surfaces, spheres, brick counts from one brick to bricks of one cell, and slabs from one plane to whole layers.
TEST(GridSet, FillEqualsTheSingleGridsFill) {
  testing::ScratchDir dir("gridset_fill");
  Scene open = testing::boxScene(0.15, 0.85);
  open.triangles.resize(10);  // the face x = 0.85 removed: a hole, decided by winding number
  Scene spheres;
  spheres.materials.push_back({});
  spheres.spheres.push_back({{0.35, 0.4, 0.5}, 0.25, {}, 0});
  spheres.spheres.push_back({{0.7, 0.6, 0.45}, 0.2, {}, 0});
  Scene twoBoxes = testing::boxScene(0.1, 0.45);
  for (const Triangle& t : testing::boxScene(0.5, 0.9).triangles) twoBoxes.triangles.push_back(t);
  const Scene bunny = loadScene(std::string(VOX_SEED_DIR) + "/meshes/bun_zipper.ply");  // scanned, open
  struct Case {
    const char* name;
    const Scene* scene;
    std::array<uint32_t, 3> dims;
    FillRule rule;
  };
  const Case cases[] = {{"closed boxes", &twoBoxes, {9, 8, 7}, FillRule::Enclosed},
                        {"open box", &open, {9, 8, 7}, FillRule::WindingNumber},
                        {"spheres", &spheres, {13, 9, 10}, FillRule::Enclosed},
                        {"open bunny", &bunny, {26, 25, 20}, FillRule::WindingNumber}};
  for (const Case& c : cases) {
    VoxelizeOptions o;
    o.dims = c.dims;
    if (c.scene != &bunny) o.bounds = Box{{0, 0, 0}, {1, 1, 1}};
    Grid single = voxelizeScene(*c.scene, o);
    const FillReport want = fillSolid(single, *c.scene);
    ASSERT_EQ(want.rule, c.rule) << c.name;
    ASSERT_GT(want.solidCells, 10u) << c.name;
    // Bricks of one cell for the small grids (a file each); the bunny's grid in bricks of a few cells.
    const std::array<uint32_t, 3> finest = c.scene == &bunny ? std::array<uint32_t, 3>{13, 5, 4} : c.dims;
    // Slabs of one plane, of a few planes and of whole layers (the default).
    const uint64_t slabCells[] = {1, 60, FillOptions{}.slabCells};
    int turn = 0;
    for (const auto bricks : {std::array<uint32_t, 3>{1, 1, 1}, {7, 5, 3}, {2, 1, 4}, {1, 3, 1}, finest}) {
      const std::string path = dir.file("f.vgrid");
      std::filesystem::remove_all(dir.file("f.bricks"));
      FillOptions fo;
      fo.slabCells = slabCells[turn++ % 3];
      FillReport got;
      const GridSetManifest m = writeGridSet(path, *c.scene, o, bricks, nullptr, &fo, &got);
      const std::string what = std::string(c.name) + " in " + std::to_string(bricks[0]) + "x" +
                               std::to_string(bricks[1]) + "x" + std::to_string(bricks[2]) + " bricks";
      EXPECT_EQ(got.solidCells, want.solidCells) << what;
      EXPECT_EQ(got.rule, want.rule) << what;
      const GridFile set = readGridSet(path);
      expectSameGrid(set.grid, single);
      ASSERT_EQ(set.grid.solidRuns.size(), single.solidRuns.size()) << what;
      for (size_t r = 0; r < single.solidRuns.size(); ++r) {
        EXPECT_EQ(set.grid.solidRuns[r].first, single.solidRuns[r].first) << what << " run " << r;
        EXPECT_EQ(set.grid.solidRuns[r].count, single.solidRuns[r].count) << what << " run " << r;
      }
      uint64_t solid = 0;
      for (const BrickEntry& e : m.entries) solid += e.solid;
      EXPECT_EQ(solid, want.solidCells) << what;
    }
  }
}

// Issue 45, defect 4: a hollow box (an outer shell facing out, an inner one facing in) filled as --fraction fills it,
// by winding number (the cavity stays empty); the flood fill a re-voxelized set runs would fill the cavity too.
struct HollowBox {
  Scene scene = testing::boxScene(0.1, 0.9);
  Grid grid;
};
HollowBox hollowBox(std::array<uint32_t, 3> dims) {
  HollowBox b;
  for (Triangle t : testing::boxScene(0.3, 0.7).triangles) {
    std::swap(t.v[1], t.v[2]);  // inward
    b.scene.triangles.push_back(t);
  }
  VoxelizeOptions o;
  o.dims = dims;
  o.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  b.grid = voxelizeScene(b.scene, o);
  fillSolid(b.grid, b.scene, fillForFractions({}));
  return b;
}

void expectSameRuns(const Grid& a, const Grid& b, const std::string& what) {
  ASSERT_EQ(a.solidRuns.size(), b.solidRuns.size()) << what;
  for (size_t r = 0; r < a.solidRuns.size(); ++r) {
    EXPECT_EQ(a.solidRuns[r].first, b.solidRuns[r].first) << what << " run " << r;
    EXPECT_EQ(a.solidRuns[r].count, b.solidRuns[r].count) << what << " run " << r;
  }
}

TEST(GridSet, AGridWrittenAsASetReadsBackAsTheGrid) {
  testing::ScratchDir dir("gridset_as_set");
  const HollowBox box = hollowBox({14, 13, 12});
  Grid flooded = box.grid;
  fillSolid(flooded, box.scene);
  ASSERT_GT(flooded.solidCount(), box.grid.solidCount());  // the case re-voxelizing got wrong: the fills differ
  ASSERT_GT(box.grid.solidCount(), 100u);
  for (const auto bricks : {std::array<uint32_t, 3>{1, 1, 1}, {2, 2, 2}, {7, 5, 3}, {14, 1, 12}, {14, 13, 12}}) {
    const std::string what =
        std::to_string(bricks[0]) + "x" + std::to_string(bricks[1]) + "x" + std::to_string(bricks[2]) + " bricks";
    const std::string path = dir.file("h.vgrid");
    const GridSetManifest m = writeGridAsSet(path, box.scene, box.grid, bricks);
    const GridFile set = readGridSet(path);
    expectSameGrid(set.grid, box.grid);
    expectSameRuns(set.grid, box.grid, what);
    EXPECT_EQ(encodeGridFile(set.scene, set.grid), encodeGridFile(box.scene, box.grid)) << what;
    EXPECT_EQ(readGridSetManifest(path).entries.size(), m.entries.size()) << what;
    // Only this set's files are left: the manifest, the scene file, its bricks.
    EXPECT_EQ(setFiles(dir).size(), 2 + m.entries.size()) << what;
  }
}

// Defects 4 and 5: a refusal (distances or fractions, which a set cannot hold; bricks out of range) or a cancel comes
// before the old output is replaced: the old set stays whole and no new file is left.
TEST(GridSet, AGridAsASetIsRefusedOrCancelledBeforeTheOldOutputIsReplaced) {
  testing::ScratchDir dir("gridset_as_set_keep");
  const HollowBox box = hollowBox({10, 9, 8});
  const std::string path = dir.file("h.vgrid");
  writeGridAsSet(path, box.scene, box.grid, {2, 2, 2});
  const std::vector<std::string> before = setFiles(dir);
  const std::string manifest = slurp(path);
  Grid withFractions = box.grid;
  withFractions.fractions.assign(withFractions.occupiedCount(), 0.5);
  Grid withBand = box.grid;
  withBand.sdfHalfWidth = 2;
  withBand.sdfKeys = {0};
  withBand.sdfValues = {0.25};
  for (const Grid* g : {&withFractions, &withBand}) {
    try {
      writeGridAsSet(path, box.scene, *g, {2, 2, 2});
      ADD_FAILURE() << "wrote a set that drops the grid's distances or fractions";
    } catch (const UsageError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("bricks: a grid set holds no signed distances or volume fractions", 0), 0u)
          << e.what();
    }
  }
  EXPECT_THROW(writeGridAsSet(path, box.scene, box.grid, {11, 1, 1}), UsageError);
  for (const int calls : {1, 2, 5, 9}) {
    auto left = std::make_shared<int>(calls);
    EXPECT_THROW(writeGridAsSet(path, box.scene, box.grid, {3, 2, 2}, [left](double) { return --*left > 0; }), Error);
  }
  EXPECT_EQ(setFiles(dir), before);
  EXPECT_EQ(slurp(path), manifest);
  expectSameRuns(readGridSet(path).grid, box.grid, "the old set");
}

// A closed box in a 9x8x7 grid over the unit cube, filled, so that solid runs cross brick faces.
struct FilledBox {
  Scene scene = testing::boxScene(0.1, 0.8);
  VoxelizeOptions options;
  Grid grid;
};
FilledBox filledBox() {
  FilledBox b;
  b.options.dims = std::array<uint32_t, 3>{9, 8, 7};
  b.options.bounds = Box{{0, 0, 0}, {1, 1, 1}};
  b.grid = voxelizeScene(b.scene, b.options);
  fillSolid(b.grid, b.scene);
  return b;
}

// The box written as a filled set NAME.vgrid in `bricks` (over any earlier one); returns the manifest's path.
std::string writeFilledBoxSet(const testing::ScratchDir& dir, const std::string& name, const FilledBox& box,
                              const std::array<uint32_t, 3>& bricks) {
  const std::string path = dir.file(name + ".vgrid");
  std::filesystem::remove_all(dir.file(name + ".bricks"));
  const FillOptions fo;
  writeGridSet(path, box.scene, box.options, bricks, nullptr, &fo);
  return path;
}

// vox-info streams a set one layer of bricks at a time; its report is the single grid's, byte for byte.
TEST(GridSet, StreamedInfoEqualsTheSingleGrids) {
  testing::ScratchDir dir("gridset_info");
  const FilledBox box = filledBox();
  const GridFile file{box.scene, box.grid};
  for (const auto bricks : {std::array<uint32_t, 3>{1, 1, 1}, {3, 2, 4}, {9, 8, 7}}) {
    const std::string path = writeFilledBoxSet(dir, "i", box, bricks);
    for (const InfoOptions io : {InfoOptions{false, false, false}, InfoOptions{true, true, true}}) {
      std::ostringstream out;
      writeGridSetInfo(out, path, io);
      EXPECT_EQ(out.str(), formatGridInfo(file, io));
    }
  }
}

// The layers as the voxel formats read them: sorted keys alone (binvox, .vox without colours) or sorted keys with
// their primitive counts (.vox by count), never a primitive list; one layer per bz, together the single grid's.
TEST(GridSet, LayersOfKeysAndCountsAreTheSingleGrids) {
  testing::ScratchDir dir("gridset_layers");
  const FilledBox box = filledBox();
  std::vector<uint64_t> wantCounts;
  for (size_t c = 0; c < box.grid.occupiedCount(); ++c) wantCounts.push_back(box.grid.cellPrims(c).size());
  for (const auto bricks : {std::array<uint32_t, 3>{1, 1, 1}, {3, 2, 4}, {2, 8, 1}, {9, 8, 7}}) {
    const std::string path = writeFilledBoxSet(dir, "l", box, bricks);
    const GridSetManifest m = readGridSetManifest(path);
    const GridFile sceneFile = readGridSetScene(path, m);
    for (const LayerCells cells : {LayerCells::KeysOnly, LayerCells::KeysAndCounts}) {
      const std::string what = std::to_string(bricks[0]) + "x" + std::to_string(bricks[1]) + "x" +
                               std::to_string(bricks[2]) + (cells == LayerCells::KeysOnly ? " keys" : " counts");
      Grid joined;
      std::vector<uint64_t> counts;
      uint32_t layers = 0;
      forEachGridSetLayer(
          path, m, sceneFile,
          [&](const Grid& layer) {
            ++layers;
            EXPECT_TRUE(layer.primIds.empty()) << what;  // no primitive list is kept
            EXPECT_EQ(layer.cellStart.size(), cells == LayerCells::KeysOnly ? 0 : layer.cellKeys.size() + 1) << what;
            for (size_t c = 0; c + 1 < layer.cellStart.size(); ++c)
              counts.push_back(layer.cellStart[c + 1] - layer.cellStart[c]);
            joined.cellKeys.insert(joined.cellKeys.end(), layer.cellKeys.begin(), layer.cellKeys.end());
            for (const CellRun& r : layer.solidRuns) appendSolidRun(joined.solidRuns, r);
          },
          cells);
      EXPECT_EQ(layers, bricks[2]) << what;
      EXPECT_EQ(joined.cellKeys, box.grid.cellKeys) << what;
      if (cells == LayerCells::KeysAndCounts) {
        EXPECT_EQ(counts, wantCounts) << what;
      }
      ASSERT_EQ(joined.solidRuns.size(), box.grid.solidRuns.size()) << what;
      for (size_t r = 0; r < joined.solidRuns.size(); ++r) {
        EXPECT_EQ(joined.solidRuns[r].first, box.grid.solidRuns[r].first) << what;
        EXPECT_EQ(joined.solidRuns[r].count, box.grid.solidRuns[r].count) << what;
      }
    }
  }
}

// `n` small triangles scattered over the unit cube, each of its own material and colour: more than 255 voxel
// colours, so a .vox palette is reduced by median cut, weighted by the voxels of every colour.
Scene manyColorScene(int n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.05, 0.95), d(-0.04, 0.04), c(0, 1);
  Scene scene;
  for (int i = 0; i < n; ++i) {
    Material mat;
    mat.diffuse = {c(rng), c(rng), c(rng)};
    scene.materials.push_back(mat);
    const Vec3 p{u(rng), u(rng), u(rng)};
    Triangle t;
    for (Vec3& v : t.v) v = p + Vec3{d(rng), d(rng), d(rng)};
    t.material = uint32_t(i);
    scene.triangles.push_back(t);
  }
  return scene;
}

// vox-export writes binvox and .vox from a set's layers of bricks (writeGridSetVoxelFile) instead of assembling it:
// each file and report is the single grid's, byte for byte, in every colour mode, with solid runs crossing bricks
// (fill), bricks of one cell, layers of several bricks, a grid of several 256^3 models on x and z whose layers are
// thinner than a model's slab or straddle two, and a palette reduced from the colours of every layer.
TEST(GridSet, VoxelFilesFromLayersEqualTheSingleGrids) {
  testing::ScratchDir dir("gridset_voxelfiles");
  const FilledBox small = filledBox();
  FilledBox thick;
  thick.options.dims = std::array<uint32_t, 3>{400, 5, 520};
  thick.options.bounds = small.options.bounds;
  thick.grid = voxelizeScene(thick.scene, thick.options);
  fillSolid(thick.grid, thick.scene);
  FilledBox colorful;  // not filled: its triangles enclose nothing
  colorful.scene = manyColorScene(400);
  colorful.options.dims = std::array<uint32_t, 3>{24, 22, 20};
  colorful.options.bounds = small.options.bounds;
  colorful.grid = voxelizeScene(colorful.scene, colorful.options);
  // 2^63 cells: keys take 63 bits, so a layer's counts of 2 cannot be packed under them and are sorted beside them
  // (LayerCells::KeysAndCounts); two tiny triangles in one cell at x > 1/2, one lower in z at x < 1/2, so that the
  // bricks' cells interleave. Too large for binvox.
  FilledBox huge;
  huge.scene = Scene{};
  huge.scene.materials.push_back({});
  for (const Vec3 at : {Vec3{0.7, 0.5, 0.2}, Vec3{0.7, 0.5, 0.2}, Vec3{0.2, 0.5, 0.4}})
    huge.scene.triangles.push_back({{at, at + Vec3{1e-7, 0, 0}, at + Vec3{0, 1e-7, 0}}, 0});
  huge.options.dims = std::array<uint32_t, 3>{kMaxCellsPerAxis, kMaxCellsPerAxis, kMaxCellsPerAxis};
  huge.options.bounds = small.options.bounds;
  huge.grid = voxelizeScene(huge.scene, huge.options);
  struct Case {
    const char* name;
    const FilledBox* box;
    bool fill;
    std::vector<std::array<uint32_t, 3>> bricks;
  };
  const Case cases[] = {{"box", &small, true, {{1, 1, 1}, {3, 2, 4}, {2, 8, 1}, {9, 8, 7}}},
                        {"thick box", &thick, true, {{1, 1, 1}, {2, 1, 3}, {1, 2, 7}}},
                        {"colourful", &colorful, false, {{1, 1, 1}, {2, 3, 4}}},
                        {"2^63 cells", &huge, false, {{2, 1, 2}}}};
  bool reduced = false;
  for (const Case& c : cases) {
    for (const auto& bricks : c.bricks) {
      const std::string path = dir.file("v.vgrid");
      std::filesystem::remove_all(dir.file("v.bricks"));
      const FillOptions fo;
      writeGridSet(path, c.box->scene, c.box->options, bricks, nullptr, c.fill ? &fo : nullptr);
      const GridSetManifest m = readGridSetManifest(path);
      const GridFile sceneFile = readGridSetScene(path, m);
      for (const VoxelFormat format : {VoxelFormat::Binvox, VoxelFormat::MagicaVoxel}) {
        for (const ColorMode color : {ColorMode::Count, ColorMode::Material, ColorMode::None}) {
          if (format == VoxelFormat::Binvox && (color != ColorMode::Count || c.box == &huge)) continue;  // no colour
          const std::string what = std::string(c.name) + " in " + std::to_string(bricks[0]) + "x" +
                                   std::to_string(bricks[1]) + "x" + std::to_string(bricks[2]) + " bricks, " +
                                   colorModeName(color) + (format == VoxelFormat::Binvox ? ", binvox" : ", vox");
          const std::vector<Rgb8> colors = format == VoxelFormat::MagicaVoxel
                                               ? occupiedCellColors(c.box->grid, c.box->scene, color)
                                               : std::vector<Rgb8>{};
          const VoxelFileReport want = writeVoxelFile(dir.file("want"), format, c.box->grid, colors);
          const VoxelFileReport got = writeGridSetVoxelFile(dir.file("got"), format, path, m, sceneFile, color);
          EXPECT_EQ(slurp(dir.file("got")), slurp(dir.file("want"))) << what;
          EXPECT_EQ(got.voxels, want.voxels) << what;
          EXPECT_EQ(got.models, want.models) << what;
          EXPECT_EQ(got.gridColors, want.gridColors) << what;
          EXPECT_EQ(got.paletteColors, want.paletteColors) << what;
          EXPECT_EQ(got.paletteReduced, want.paletteReduced) << what;
          if (format == VoxelFormat::MagicaVoxel && c.box == &thick) {
            EXPECT_EQ(got.models, 4u) << what;  // 2 x 1 x 2 tiles
          }
          reduced = reduced || got.paletteReduced;
        }
      }
    }
  }
  EXPECT_TRUE(reduced);  // the weighted median cut was exercised
}

// Brick and scene files are untrusted: every truncation and bit flip of a brick is refused with its name, and a
// brick of another scene, a scene file of another set and an old-version manifest are refused.
TEST(GridSet, CorruptBricksAndForeignSceneFilesAreRefused) {
  testing::ScratchDir dir("gridset_brick");
  VoxelizeOptions o;
  o.dims = std::array<uint32_t, 3>{6, 5, 4};
  const std::string path = dir.file("s.vgrid");
  const GridSetManifest m = writeGridSet(path, sceneWithPlane(3), o, {3, 2, 2});
  const uint64_t bounded = sceneWithPlane(3).boundedCount();
  const std::string brick = slurp(dir.file(m.entries[0].file));
  for (size_t n = 0; n < brick.size(); ++n)
    EXPECT_THROW(decodeBrickFile(brick.substr(0, n), "b", m, m.entries[0], bounded), InputError);
  for (size_t bit = 0; bit < brick.size() * 8; bit += 3) {
    std::string b = brick;
    b[bit / 8] = char(b[bit / 8] ^ (1 << (bit % 8)));
    EXPECT_THROW(decodeBrickFile(b, "b", m, m.entries[0], bounded), InputError) << "bit " << bit;
  }
  EXPECT_NO_THROW(decodeBrickFile(brick, "b", m, m.entries[0], bounded));
  // A brick written against another scene file (checksum), with a valid header of its own.
  GridSetManifest other = m;
  other.scene.checksum ^= 1;
  const Grid cells = decodeBrickFile(brick, "b", m, m.entries[0], bounded);
  try {
    decodeBrickFile(encodeBrickFile(other, m.entries[0].index, cells), "b", m, m.entries[0], bounded);
    ADD_FAILURE() << "accepted a brick of another scene";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another scene file"), std::string::npos) << e.what();
  }
  // Primitive ids beyond the scene's.
  EXPECT_THROW(decodeBrickFile(brick, "b", m, m.entries[0], 1), InputError);
  // A brick named directly is not a grid.
  try {
    readGridOrSet(dir.file(m.entries[0].file));
    ADD_FAILURE() << "read a brick as a grid";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("manifest"), std::string::npos) << e.what();
  }
  // Another set's scene file in place of this one's.
  const GridSetManifest t = writeGridSet(dir.file("t.vgrid"), sceneWithPlane(4), o, {1, 1, 1});
  std::filesystem::copy_file(dir.file(t.scene.file), dir.file(m.scene.file),
                             std::filesystem::copy_options::overwrite_existing);
  try {
    readGridSet(path);
    ADD_FAILURE() << "accepted a foreign scene file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.vgrid: not the scene file"), std::string::npos) << e.what();
  }
  // Version 1 manifests (the scene in every brick) are refused with what to do.
  std::string v1 = slurp(path);
  v1[8] = 1;
  try {
    decodeGridSetManifest(v1, "old.vgrid");
    ADD_FAILURE() << "accepted version 1";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("voxelize the scene again"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vox
