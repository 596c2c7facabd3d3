// The grid flags vox-voxelize and vox-voxelize-mpi share (--method, --grid, --res, --bounds) as the voxelizer's
// options, with the memory budget every voxelization runs under.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vox/core/memory_budget.h"
#include "vox/voxelize/voxelize.h"

namespace vox::cli {

// `grid` is empty or NX NY NZ, `bounds` empty or 6 numbers (CLI11 has checked the counts); resolution 0: not given.
// Throws InputError for an unknown method.
inline VoxelizeOptions voxelizeOptionsFromFlags(const std::string& method, const std::vector<uint32_t>& grid,
                                                uint32_t resolution, const std::vector<double>& bounds) {
  VoxelizeOptions vo;
  vo.method = parseMethod(method);
  if (!grid.empty()) vo.dims = std::array<uint32_t, 3>{grid[0], grid[1], grid[2]};
  if (resolution) vo.resolution = resolution;
  if (!bounds.empty()) vo.bounds = Box{{bounds[0], bounds[1], bounds[2]}, {bounds[3], bounds[4], bounds[5]}};
  vo.memoryLimitBytes = memoryBudgetBytes();
  return vo;
}

}  // namespace vox::cli
