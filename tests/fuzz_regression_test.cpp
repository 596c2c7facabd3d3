// Every input saved from a fuzzing run (tests/data/fuzz/<target>/, one folder per target of fuzz/) replays through
// the code of the target that found it (fuzz/fuzz_entry.h): it loads, or it is refused with vox::Error.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "../fuzz/fuzz_entry.h"

namespace vox {
namespace {

// Target name -> scene file extension (the grid target, grid files and grid sets, has its own entry point).
const std::map<std::string, std::string> kSceneTargets{
    {"course", "txt"}, {"obj", "obj"}, {"ply", "ply"}, {"gltf", "gltf"}, {"glb", "glb"}};

TEST(FuzzRegression, SavedInputsLoadOrAreRefused) {
  const std::filesystem::path root = std::filesystem::path(VOX_SOURCE_DIR) / "tests/data/fuzz";
  if (!std::filesystem::is_directory(root)) GTEST_SKIP() << "no saved inputs in " << root;
  int replayed = 0;
  for (const auto& folder : std::filesystem::directory_iterator(root)) {
    const std::string target = folder.path().filename().string();
    ASSERT_TRUE(target == "grid" || target == "voxel_writers" || kSceneTargets.count(target))
        << "unknown fuzz target folder " << folder.path();
    // voxel_writers replays under its target's budget in voxel_formats_test.cpp (FuzzVoxelWriters).
    if (target == "voxel_writers") continue;
    for (const auto& entry : std::filesystem::directory_iterator(folder.path())) {
      SCOPED_TRACE(entry.path().string());
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string bytes{std::istreambuf_iterator<char>(in), {}};
      if (target == "grid")
        EXPECT_NO_THROW(fuzz::readGridInput(bytes));
      else
        EXPECT_NO_THROW(fuzz::loadSceneBytes(bytes, kSceneTargets.at(target)));
      ++replayed;
    }
  }
  RecordProperty("replayed", replayed);
}

}  // namespace
}  // namespace vox
