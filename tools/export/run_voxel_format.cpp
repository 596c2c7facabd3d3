// vox-export to voxel formats (.binvox, .vox, .vdb).
#include <filesystem>

#include "runs.h"
#include "vox/core/progress.h"
#include "vox/core/tool.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_set.h"

namespace vox::export_tool {

int runVoxelFormat(const Options& opt, VoxelFormat format) {
  const auto start = std::chrono::steady_clock::now();
  auto threads = cli::limitThreads(opt.common.threads);
  checkOutputPath(opt.output, {opt.grid});
  const ColorMode color = parseColorMode(opt.color);
  ProgressBar bar("exporting", opt.common.quiet);
  // binvox and .vox need only the voxels in key order (with each occupied cell's colour for .vox): a set is then
  // read one layer of bricks at a time on each of the writer's passes instead of assembled, which keeps the peak
  // memory to a layer (docs/scaling.md). .vdb builds OpenVDB's tree of the whole grid, so its set is assembled.
  const bool layered = format != VoxelFormat::Vdb && format != VoxelFormat::Npz && isGridSet(opt.grid);
  GridSetManifest set;
  GridFile file;
  if (layered) {
    set = readGridSetManifest(opt.grid);
    file = readGridSetScene(opt.grid, set);
  } else {
    file = readGridOrSet(opt.grid);
  }
  uint64_t occupied = file.grid.occupiedCount(), solid = file.grid.solidCount();
  for (const BrickEntry& e : set.entries) {
    occupied += e.occupied;
    solid += e.solid;
  }
  bar.update(0.1);
  std::vector<Rgb8> colors;
  if (!layered && format == VoxelFormat::MagicaVoxel && color != ColorMode::None)
    colors = namingGrid(opt, [&] { return occupiedCellColors(file.grid, file.scene, color); });
  bar.update(0.2);
  const auto writeStart = std::chrono::steady_clock::now();
  const auto progress = [&](double f) { bar.update(0.2 + 0.8 * f); };
  const VoxelFileReport report = namingGrid(opt, [&] {
    return layered ? writeGridSetVoxelFile(opt.output, format, opt.grid, set, file, color, progress)
                   : writeVoxelFile(opt.output, format, file.grid, colors, progress);
  });
  const double writeSeconds = secondsSince(writeStart);
  bar.finish();
  if (format == VoxelFormat::Binvox && report.binvoxShiftVoxels > 1e-9 && !opt.common.quiet)
    std::fprintf(stderr,
                 "vox-export: warning: %s: binvox voxels are cubes; the grid's cells are not, so they are written as "
                 "cubes of side %.9g (the longest axis' cell) and the grid's far face moves by up to %.3g voxels\n",
                 opt.output.c_str(), report.binvoxVoxelSide, report.binvoxShiftVoxels);
  if (report.paletteReduced && !opt.common.quiet)
    std::fprintf(stderr, "vox-export: warning: %s: %u voxel colours reduced to a palette of %u (median cut)\n",
                 opt.output.c_str(), report.gridColors, report.paletteColors);
  if (opt.stats) {
    std::error_code sizeError;
    const auto bytes = std::filesystem::file_size(opt.output, sizeError);
    std::fprintf(stderr,
                 "voxels: %llu\noccupied_cells: %zu\nsolid_cells: %llu\n%s: %llu\ncolors: %u\n"
                 "palette_colors: %u\noutput_bytes: %llu\nwrite_seconds: %.6f\ntotal_seconds: %.6f\n",
                 (unsigned long long)report.voxels, size_t(occupied), (unsigned long long)solid,
                 format == VoxelFormat::Vdb ? "vdb_leaf_nodes" : "models", (unsigned long long)report.models,
                 report.gridColors, report.paletteColors, (unsigned long long)(sizeError ? 0 : bytes), writeSeconds,
                 secondsSince(start));
  }
  return kExitOk;
}

}  // namespace vox::export_tool
