// vox-voxelize-mpi's batches (tools/voxelize-mpi/batch.cpp): the list read, each scene's output named, and one
// scene voxelized into the grid vox-voxelize makes. No mpirun needed.
#include "voxelize-mpi/batch.h"

#include <gtest/gtest.h>

#include <fstream>

#include "test_util.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/fill.h"

namespace vox::mpi {
namespace {

TEST(VoxelizeMpiBatch, ListSkipsBlanksAndComments) {
  const testing::ScratchDir dir("mpi_batch_list");
  std::ofstream(dir.file("list.txt")) << "# scenes\na.obj  \r\n\n\t\nsub/b.ply\t\n#c.obj\nc d.glb";
  EXPECT_EQ(readBatchList(dir.file("list.txt")), (std::vector<std::string>{"a.obj", "sub/b.ply", "c d.glb"}));
  std::ofstream(dir.file("empty.txt")) << "# nothing\n\n";
  EXPECT_THROW(readBatchList(dir.file("empty.txt")), InputError);
  EXPECT_THROW(readBatchList(dir.file("missing.txt")), InputError);
}

TEST(VoxelizeMpiBatch, OutputsNamedByStemAndNeverShared) {
  EXPECT_EQ(batchOutputs("l", {"a.obj", "x/b.ply"}, "out"), (std::vector<std::string>{"out/a.vgrid", "out/b.vgrid"}));
  try {
    batchOutputs("l.txt", {"x/a.obj", "y/a.ply"}, "out");
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_STREQ(e.what(), "l.txt: two scenes would both write a.vgrid (x/a.obj and y/a.ply)");
  }
  EXPECT_THROW(batchOutputs("l.txt", {"dir/"}, "out"), InputError);
}

TEST(VoxelizeMpiBatch, OneSceneIsVoxelizeToolsGrid) {
  const testing::ScratchDir dir("mpi_batch_one");
  const std::string scene = std::string(VOX_SOURCE_DIR) + "/scenes/scene5_07_bunny_mesh_1k.txt";
  makeOutputFolder(dir.file("out"));
  makeOutputFolder(dir.file("out"));  // an existing folder is fine
  Options opt;
  opt.resolution = 16;
  opt.fill = true;
  voxelizeOne(opt, scene, dir.file("out/bunny.vgrid"));
  const GridFile got = readGridFile(dir.file("out/bunny.vgrid"));
  const Scene s = loadScene(scene);
  VoxelizeOptions vo;
  vo.resolution = 16;
  Grid want = voxelizeScene(s, vo);
  fillSolid(want, s, FillOptions{vo.memoryLimitBytes, {}, {}, false});
  EXPECT_EQ(got.grid.dims, want.dims);
  EXPECT_EQ(got.grid.cellKeys, want.cellKeys);
  EXPECT_EQ(got.grid.primIds, want.primIds);
  EXPECT_EQ(got.grid.solidCount(), want.solidCount());
  std::ofstream(dir.file("file")) << "x";
  EXPECT_THROW(makeOutputFolder(dir.file("file")), OutputError);
  try {
    voxelizeOne(opt, dir.file("file"), dir.file("out/file.vgrid"));  // not a scene: named in the message
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("file")), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vox::mpi
