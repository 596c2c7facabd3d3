// Helpers shared by the grid file section tests: a small grid of a scene, and a patched file made valid again.
#pragma once

#include <cstring>
#include <string>

#include "vox/io/grid_file.h"
#include "vox/voxelize/voxelize.h"

namespace vox::testing {

// The grid of `scene` in n x n x n cells.
inline Grid smallGrid(const Scene& scene, uint32_t n) {
  VoxelizeOptions options;
  options.dims = {n, n, n};
  return voxelizeScene(scene, options);
}

// `bytes`, a grid file whose payload was patched or cut, with its header's payload size and checksum recomputed, so
// that the decoder reaches the patched place instead of refusing the checksum.
inline std::string resealed(std::string bytes) {
  constexpr size_t kHeader = 32;
  const uint64_t size = bytes.size() - kHeader;
  std::memcpy(&bytes[16], &size, 8);
  const uint64_t sum = gridChecksum(bytes.data() + kHeader, size);
  std::memcpy(&bytes[24], &sum, 8);
  return bytes;
}

}  // namespace vox::testing
