// What every fuzz target runs, shared with tests/fuzz_regression_test.cpp so that a saved finding replays through
// exactly the code that found it. An input may be refused with vox::Error; any other exception, a signal, a
// sanitizer report or a hang is a finding.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/io/grid_file.h"
#include "vox/import/import.h"
#include "vox/trace/render.h"
#include "vox/export/voxel_mesh.h"

namespace vox::fuzz {

// A folder of this process's own under $TMPDIR (so parallel fuzzers never share an input file), removed at exit.
// Leaked on purpose: it must outlive the static destructors that run before the atexit handler.
inline const std::string& privateFolder() {
  static const std::string* folder = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "vox-fuzz-XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    auto* made = new std::string(pattern);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(privateFolder(), ignored);
    });
    return made;
  }();
  return *folder;
}

// Writes `bytes` to input.EXTENSION in the private folder and loads it through loadScene, as vox-voxelize does:
// the importers take a path, and the extension picks the importer (txt, obj, ply, gltf, glb).
inline void loadSceneBytes(std::string_view bytes, const std::string& extension) {
  const std::string path = privateFolder() + "/input." + extension;
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) std::abort();
  }
  try {
    loadScene(path);
  } catch (const Error&) {
  }
}

// What a decoded grid file must survive: tracing in three modes and meshing. vox::Error is an acceptable answer,
// a crash is not. Shared by the fuzz target and tests/grid_file_test.cpp's structure fuzzing.
inline void exerciseDecodedGrid(const GridFile& file) {
  try {
    const Accel accel = buildAccel(file.scene, file.grid, AccelKind::Grid);
    RenderOptions options;
    options.width = options.height = 6;
    const auto bounds = sceneBounds(file.scene);
    options.camera = file.scene.camera ? *file.scene.camera : defaultCamera(bounds ? *bounds : file.grid.bounds);
    for (RenderMode mode : {RenderMode::Shade, RenderMode::Voxels, RenderMode::Depth}) {
      options.mode = mode;
      traceImage(file.scene, accel, options);
    }
    buildVoxelMesh(file.grid, file.scene, FaceMode::Exposed, ColorMode::Count);
    buildVoxelMesh(file.grid, file.scene, FaceMode::Merged, ColorMode::Material);
  } catch (const Error&) {
  }
}

// Decodes `bytes` as a grid file after rewriting the header's payload size (offset 16) and checksum (offset 24),
// so that mutations reach the reader's own checks of counts, offsets and ids instead of stopping at the checksum
// (docs/grid-format.md). What decodes is traced and exported (exerciseDecodedGrid).
inline void decodeGridBytes(std::string bytes) {
  constexpr size_t kHeader = 32;
  if (bytes.size() >= kHeader) {
    const uint64_t size = bytes.size() - kHeader;
    const uint64_t sum = gridChecksum(bytes.data() + kHeader, size);
    std::memcpy(&bytes[16], &size, 8);
    std::memcpy(&bytes[24], &sum, 8);
  }
  GridFile file;
  try {
    file = decodeGridFile(bytes, "fuzz.vgrid");
  } catch (const Error&) {
    return;
  }
  exerciseDecodedGrid(file);
}

}  // namespace vox::fuzz
