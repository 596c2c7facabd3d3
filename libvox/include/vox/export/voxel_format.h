// The voxel file formats of vox-export (binvox, MagicaVoxel .vox, OpenVDB .vdb), chosen by the output's extension,
// and one entry point that writes any of them through an OutputFile (temporary file and rename).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "vox/core/grid.h"
#include "vox/export/voxel_mesh.h"
#include "vox/export/voxel_runs.h"

namespace vox {

enum class VoxelFormat : uint8_t { Binvox, MagicaVoxel, Vdb };

// The voxel format of `path`'s extension (.binvox, .vox, .vdb; case-insensitive), or nullopt for any other.
std::optional<VoxelFormat> voxelFormatFromPath(const std::string& path);

// What was written, for the tool's --stats and warnings.
struct VoxelFileReport {
  uint64_t voxels = 0;          // occupied and solid cells written
  uint64_t models = 0;          // .vox: models (256^3 tiles); .vdb: leaf nodes of `density`
  uint32_t gridColors = 0;      // .vox: distinct voxel colours
  uint32_t paletteColors = 0;   // .vox: palette size
  bool paletteReduced = false;  // .vox: more than 255 colours, reduced by median cut
  double binvoxShiftVoxels = 0; // .binvox: how far non-cubic cells move the grid's far face (BinvoxLayout)
  double binvoxVoxelSide = 0;   // .binvox: the cube side written
};

// Writes the voxels of `grid` to `path` in `format` (binvox_writer.h, magicavoxel_writer.h, vdb_writer.h).
// cellColors: .vox only, one colour per occupied cell (see writeMagicaVoxel); solid-only cells get kSolidCellColor.
// Throws what the writers throw, and OutputError when the file cannot be written (the old file is then untouched).
VoxelFileReport writeVoxelFile(const std::string& path, VoxelFormat format, const Grid& grid,
                               std::span<const Rgb8> cellColors, const std::function<void(double)>& progress = {});

// binvox from the plan of a grid and a source of its voxel rows (writeBinvox's second form): what vox-export does for
// a grid set, whose bricks are then read one layer at a time instead of assembled. The same file and report as
// writeVoxelFile(Binvox) of the grid.
VoxelFileReport writeBinvoxFile(const std::string& path, const Grid& plan, const VoxelRowSource& rows,
                                const std::function<void(double)>& progress = {});

}  // namespace vox
