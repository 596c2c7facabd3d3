// Voxel file formats (voxel_format.h): extension dispatch over the three writers.
#include "vox/export/voxel_format.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "vox/export/binvox_writer.h"
#include "vox/export/magicavoxel_writer.h"
#include "vox/export/vdb_writer.h"
#include "vox/export/voxel_runs.h"
#include "vox/io/atomic_file.h"

namespace vox {

namespace {

// binvox from a row source into `out`; the voxels are counted on the writer's passes over the rows (each pass counts
// them all; the last count stands), so no pass of its own.
void writeBinvoxRows(std::ostream& out, const Grid& plan, const VoxelRowSource& rows,
                     const std::function<void(double)>& progress, VoxelFileReport& report) {
  const VoxelRowSource counting = [&](const std::function<void(const VoxelRow&)>& visit) {
    uint64_t voxels = 0;
    rows([&](const VoxelRow& r) {
      voxels += r.count;
      visit(r);
    });
    report.voxels = voxels;
  };
  const BinvoxLayout layout = writeBinvox(out, plan, counting, progress);
  report.binvoxShiftVoxels = layout.farFaceShiftVoxels;
  report.binvoxVoxelSide = layout.voxelSide;
}

}  // namespace

std::optional<VoxelFormat> voxelFormatFromPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".binvox") return VoxelFormat::Binvox;
  if (ext == ".vox") return VoxelFormat::MagicaVoxel;
  if (ext == ".vdb") return VoxelFormat::Vdb;
  return std::nullopt;
}

VoxelFileReport writeVoxelFile(const std::string& path, VoxelFormat format, const Grid& grid,
                               std::span<const Rgb8> cellColors, const std::function<void(double)>& progress) {
  VoxelFileReport report;
  OutputFile file(path);
  switch (format) {
    case VoxelFormat::Binvox:
      writeBinvoxRows(file.stream(), grid, voxelRows(grid), progress, report);
      break;
    case VoxelFormat::MagicaVoxel: {
      const MagicaVoxelStats s = writeMagicaVoxel(file.stream(), grid, cellColors, kSolidCellColor, progress);
      report.voxels = s.voxels;
      report.models = s.models;
      report.gridColors = s.gridColors;
      report.paletteColors = s.paletteColors;
      report.paletteReduced = s.paletteReduced;
      break;
    }
    case VoxelFormat::Vdb: {
      const VdbStats s = writeVdb(file.stream(), grid, progress);
      report.voxels = s.activeVoxels;
      report.models = s.leafNodes;
      break;
    }
  }
  file.commit();
  return report;
}

VoxelFileReport writeBinvoxFile(const std::string& path, const Grid& plan, const VoxelRowSource& rows,
                                const std::function<void(double)>& progress) {
  VoxelFileReport report;
  OutputFile file(path);
  writeBinvoxRows(file.stream(), plan, rows, progress, report);
  file.commit();
  return report;
}

}  // namespace vox
