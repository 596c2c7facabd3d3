// Tests of the untrusted-input guards: folder confinement, regular files only.
#include "vox/io/input_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "vox/core/error.h"

namespace vox {
namespace {

namespace fs = std::filesystem;

struct TempFolder {
  fs::path root = fs::temp_directory_path() / ("vox_input_" + std::to_string(::getpid()));
  TempFolder() {
    fs::remove_all(root);
    fs::create_directories(root / "scene" / "sub");
    for (const char* f : {"secret.bin", "scene/a.bin", "scene/sub/b.bin"}) std::ofstream(root / f) << "x";
  }
  ~TempFolder() { fs::remove_all(root); }
  std::string scene() const { return (root / "scene" / "s.gltf").string(); }
};

TEST(InputFile, ReferencesStayInsideTheReferrersFolder) {
  const TempFolder t;
  EXPECT_EQ(resolveInsideFolder(t.scene(), "a.bin"), (fs::canonical(t.root) / "scene" / "a.bin").string());
  EXPECT_NO_THROW(resolveInsideFolder(t.scene(), "sub/b.bin"));
  EXPECT_NO_THROW(resolveInsideFolder(t.scene(), "sub/../a.bin"));
  EXPECT_NO_THROW(resolveInsideFolder(t.scene(), "./missing.bin"));  // missing is the reader's error, not this one
  for (const char* bad : {"../secret.bin", "sub/../../secret.bin", "/etc/passwd", "..", "../scene2/x"})
    EXPECT_THROW(resolveInsideFolder(t.scene(), bad), InputError) << bad;
  // A sibling folder whose name starts with the folder's name is outside.
  fs::create_directories(t.root / "scene2");
  EXPECT_THROW(requireInsideFolder(t.scene(), (t.root / "scene2" / "x").string()), InputError);
  // A symbolic link inside that leads out is outside.
  fs::create_symlink(t.root / "secret.bin", t.root / "scene" / "link.bin");
  EXPECT_THROW(resolveInsideFolder(t.scene(), "link.bin"), InputError);
  fs::create_directory_symlink(t.root, t.root / "scene" / "up");
  EXPECT_THROW(resolveInsideFolder(t.scene(), "up/secret.bin"), InputError);
}

TEST(InputFile, OnlyRegularFilesAreRead) {
  const TempFolder t;
  EXPECT_EQ(readInputFile((t.root / "secret.bin").string(), "test file"), "x");
  EXPECT_THROW(readInputFile((t.root / "scene").string(), "test file"), InputError);
  EXPECT_THROW(readInputFile((t.root / "none").string(), "test file"), InputError);
  const fs::path fifo = t.root / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(readInputFile(fifo.string(), "test file"), InputError);  // refused, not a read that blocks
  EXPECT_THROW(readInputFile("/dev/zero", "test file"), InputError);    // a device never ends
}

}  // namespace
}  // namespace vox
