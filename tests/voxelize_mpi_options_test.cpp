// vox-voxelize-mpi's options (tools/voxelize-mpi/options.cpp): the command line parsed into the struct, the
// combinations CLI11 cannot refuse, and the voxelizer's options taken from it. No mpirun needed.
#include "voxelize-mpi/options.h"

#include "common/cli_app.h"

#include <gtest/gtest.h>

#include <vector>

namespace vox::mpi {
namespace {

// Parses `args` (after the program name) as the tool does; true when CLI11 accepted them.
bool parse(std::vector<std::string> args, Options& opt) {
  CLI::App app{"test", "vox-voxelize-mpi"};
  addOptions(app, opt);
  std::vector<const char*> argv{"vox-voxelize-mpi"};
  for (const auto& a : args) argv.push_back(a.c_str());
  try {
    app.parse(int(argv.size()), const_cast<char**>(argv.data()));
    return true;
  } catch (const CLI::ParseError&) {
    return false;
  }
}

TEST(VoxelizeMpiOptions, ParsedIntoTheStruct) {
  Options opt;
  ASSERT_TRUE(parse({"s.obj", "-o", "out.vgrid", "--bricks", "2", "3", "4", "--res", "64", "--method", "sat", "--fill",
                     "--stats", "--threads", "3", "-q"},
                    opt));
  EXPECT_EQ(opt.scene, "s.obj");
  EXPECT_EQ(opt.output, "out.vgrid");
  EXPECT_EQ(opt.bricks, (std::vector<uint32_t>{2, 3, 4}));
  EXPECT_EQ(opt.resolution, 64u);
  EXPECT_EQ(opt.method, "sat");
  EXPECT_TRUE(opt.fill && opt.stats && opt.common.quiet);
  EXPECT_EQ(opt.common.threads, 3u);
  EXPECT_EQ(modeError(opt), "");
}

TEST(VoxelizeMpiOptions, RefusedCombinations) {
  Options opt;
  EXPECT_FALSE(parse({"s.obj"}, opt));                                                    // -o is required
  EXPECT_FALSE(parse({"s.obj", "-o", "o", "--grid", "2", "2", "2", "--res", "4"}, opt));  // one or the other
  EXPECT_FALSE(parse({"s.obj", "-o", "o", "--method", "nearest"}, opt));
  EXPECT_FALSE(parse({"s.obj", "-o", "o", "--bricks", "0", "1", "1"}, opt));
  Options neither;
  ASSERT_TRUE(parse({"-o", "o"}, neither));
  EXPECT_EQ(modeError(neither), "give either SCENE with --bricks or --batch LIST (see --help)");
  Options both;
  ASSERT_TRUE(parse({"s.obj", "--batch", "list.txt", "-o", "o"}, both));
  EXPECT_EQ(modeError(both), "give either SCENE with --bricks or --batch LIST (see --help)");
  Options noBricks;
  ASSERT_TRUE(parse({"s.obj", "-o", "o"}, noBricks));
  EXPECT_EQ(modeError(noBricks), "SCENE needs --bricks BX BY BZ (see --help)");
  Options batch;
  ASSERT_TRUE(parse({"--batch", "list.txt", "-o", "dir"}, batch));
  EXPECT_EQ(modeError(batch), "");
}

TEST(VoxelizeMpiOptions, VoxelizeOptionsFollowTheFlags) {
  Options opt;
  ASSERT_TRUE(parse({"s.obj", "-o",       "o", "--bricks", "1", "1", "1", "--grid", "4",        "5",
                     "6",     "--bounds", "0", "0",        "0", "1", "2", "3",      "--method", "center"},
                    opt));
  const VoxelizeOptions vo = voxelizeOptions(opt);
  EXPECT_EQ(vo.method, OverlapMethod::Center);
  ASSERT_TRUE(vo.dims.has_value());
  EXPECT_EQ(*vo.dims, (std::array<uint32_t, 3>{4, 5, 6}));
  EXPECT_FALSE(vo.resolution.has_value());
  ASSERT_TRUE(vo.bounds.has_value());
  EXPECT_EQ(vo.bounds->hi.y, 2);
  EXPECT_GT(vo.memoryLimitBytes, 0u);
  Options plain;
  ASSERT_TRUE(parse({"s.obj", "-o", "o", "--bricks", "1", "1", "1"}, plain));
  const VoxelizeOptions defaults = voxelizeOptions(plain);
  EXPECT_EQ(defaults.method, OverlapMethod::Exact);
  EXPECT_FALSE(defaults.dims || defaults.resolution || defaults.bounds);
}

}  // namespace
}  // namespace vox::mpi
