// Voxel file formats (voxel_format.h): extension dispatch over the three writers, and binvox and .vox written from
// a grid set's layers of bricks.
#include "vox/export/voxel_format.h"

#include "vox/export/npz_writer.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "vox/export/binvox_writer.h"
#include "vox/export/magicavoxel_writer.h"
#include "vox/export/npz_writer.h"
#include "vox/export/vdb_writer.h"
#include "vox/export/voxel_runs.h"
#include "vox/core/error.h"
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

void reportVox(const MagicaVoxelStats& s, VoxelFileReport& report) {
  report.voxels = s.voxels;
  report.models = s.models;
  report.gridColors = s.gridColors;
  report.paletteColors = s.paletteColors;
  report.paletteReduced = s.paletteReduced;
}

// A set's layers as .vox pieces, each with its cells' colours. By count, the ramp's top is the whole set's largest
// count, found on a pass of its own over the bricks (one at a time, unsorted): the colours of the first layer depend
// on cells of the last.
ColoredPieceSource setPieces(const std::string& setPath, const GridSetManifest& set, const GridFile& sceneFile,
                             ColorMode color) {
  const LayerCells cells = color == ColorMode::Count      ? LayerCells::KeysAndCounts
                           : color == ColorMode::Material ? LayerCells::Sorted
                                                          : LayerCells::KeysOnly;
  uint32_t maxCount = 0;
  if (color == ColorMode::Count)
    for (size_t i = 0; i < set.entries.size(); ++i)
      maxCount = std::max(maxCount, largestCellCount(readBrick(setPath, set, i, sceneFile.scene.boundedCount())));
  return [&setPath, &set, &sceneFile, color, cells, maxCount](const ColoredPieceVisitor& visit) {
    forEachGridSetLayer(
        setPath, set, sceneFile,
        [&](const Grid& layer) { visit(layer, occupiedCellColors(layer, sceneFile.scene, color, maxCount)); }, cells);
  };
}

}  // namespace

std::optional<VoxelFormat> voxelFormatFromPath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".binvox") return VoxelFormat::Binvox;
  if (ext == ".vox") return VoxelFormat::MagicaVoxel;
  if (ext == ".vdb") return VoxelFormat::Vdb;
  if (ext == ".npz") return VoxelFormat::Npz;
  return std::nullopt;
}

VoxelFileReport writeVoxelFile(const std::string& path, VoxelFormat format, const Grid& grid,
                               std::span<const Rgb8> cellColors, const std::function<void(double)>& progress) {
  VoxelFileReport report;
  checkGridBeforeWrite(grid, path);  // before the output is opened (writeNpz checks again, for its other callers)
  OutputFile file(path);
  switch (format) {
    case VoxelFormat::Binvox:
      writeBinvoxRows(file.stream(), grid, voxelRows(grid), progress, report);
      break;
    case VoxelFormat::MagicaVoxel:
      reportVox(writeMagicaVoxel(file.stream(), grid, cellColors, kSolidCellColor, progress), report);
      break;
    case VoxelFormat::Vdb: {
      const VdbStats s = writeVdb(file.stream(), grid, progress);
      report.voxels = s.activeVoxels;
      report.models = s.leafNodes;
      break;
    }
    case VoxelFormat::Npz:
      writeNpz(file.stream(), grid, progress);
      report.voxels = grid.occupiedCount() + grid.solidCount();
      break;
  }
  file.commit();
  return report;
}

VoxelFileReport writeGridSetVoxelFile(const std::string& path, VoxelFormat format, const std::string& setPath,
                                      const GridSetManifest& set, const GridFile& sceneFile, ColorMode color,
                                      const std::function<void(double)>& progress) {
  VOX_CHECK(format != VoxelFormat::Vdb && format != VoxelFormat::Npz);
  const Grid& plan = sceneFile.grid;
  VoxelFileReport report;
  OutputFile file(path);
  if (format == VoxelFormat::Binvox) {
    const VoxelRowSource rows = [&](const std::function<void(const VoxelRow&)>& visit) {
      forEachGridSetLayer(
          setPath, set, sceneFile, [&](const Grid& layer) { forEachVoxelRow(layer, visit); }, LayerCells::KeysOnly);
    };
    writeBinvoxRows(file.stream(), plan, rows, progress, report);
  } else {
    const ColoredPieceSource pieces = setPieces(setPath, set, sceneFile, color);
    reportVox(writeMagicaVoxelPieces(file.stream(), plan, pieces, kSolidCellColor, progress), report);
  }
  file.commit();
  return report;
}

}  // namespace vox
