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
#include "vox/io/grid_set.h"

namespace vox {

enum class VoxelFormat : uint8_t { Binvox, MagicaVoxel, Vdb, Npz };

// The voxel format of `path`'s extension (.binvox, .vox, .vdb, .npz; case-insensitive), or nullopt for any other.
std::optional<VoxelFormat> voxelFormatFromPath(const std::string& path);

// What was written, for the tool's --stats and warnings.
struct VoxelFileReport {
  uint64_t voxels = 0;           // occupied and solid cells written
  uint64_t models = 0;           // .vox: models (256^3 tiles); .vdb: leaf nodes of `density`
  uint32_t gridColors = 0;       // .vox: distinct voxel colours
  uint32_t paletteColors = 0;    // .vox: palette size
  bool paletteReduced = false;   // .vox: more than 255 colours, reduced by median cut
  double binvoxShiftVoxels = 0;  // .binvox: how far non-cubic cells move the grid's far face (BinvoxLayout)
  double binvoxVoxelSide = 0;    // .binvox: the cube side written
};

// Writes the voxels of `grid` to `path` in `format` (binvox_writer.h, magicavoxel_writer.h, vdb_writer.h).
// cellColors: .vox only, one colour per occupied cell (see writeMagicaVoxel); solid-only cells get kSolidCellColor.
// Throws what the writers throw, and OutputError when the file cannot be written (the old file is then untouched).
VoxelFileReport writeVoxelFile(const std::string& path, VoxelFormat format, const Grid& grid,
                               std::span<const Rgb8> cellColors, const std::function<void(double)>& progress = {});

// Writes the voxels of the grid set at `setPath` (its manifest `set` and scene file `sceneFile`, as
// readGridSetManifest and readGridSetScene return them) to `path` as binvox or .vox without assembling the set: each
// of the writer's passes reads the bricks one layer at a time (forEachGridSetLayer), keeping the layer's sorted keys
// (binvox, and .vox without colours), keys and primitive counts (.vox by count, after one more pass for the largest
// count) or keys and primitive lists (.vox by material). The same file and report as writeVoxelFile of the assembled
// grid with occupiedCellColors(grid, scene, color) as its cell colours. Memory: one layer of bricks plus the writer's
// own (binvox: run events and one plane; .vox: one 256-thick slab of voxels).
// @note format is not Vdb (OpenVDB builds its tree of the whole grid).
// Throws as writeVoxelFile, and as forEachGridSetLayer for a corrupt set.
VoxelFileReport writeGridSetVoxelFile(const std::string& path, VoxelFormat format, const std::string& setPath,
                                      const GridSetManifest& set, const GridFile& sceneFile, ColorMode color,
                                      const std::function<void(double)>& progress = {});

}  // namespace vox
