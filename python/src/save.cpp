// Grid.save: every output of vox-voxelize and vox-export, by extension, through the same library calls.
#include <cstdio>
#include <filesystem>

#include "binding.h"
#include "vox/core/error.h"
#include "vox/export/viewer_page.h"
#include "vox/export/voxel_format.h"
#include "vox/export/voxel_mesh.h"
#include "vox/io/atomic_file.h"
#include "vox/io/grid_set.h"
#include "vox/io/input_file.h"
#include "vox/voxelize/bricks.h"

namespace voxpy {

namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool isGridFilePath(const std::string& path) { return lowerExtension(path) == ".vgrid"; }
bool isViewerPagePath(const std::string& path) {
  return lowerExtension(path) == ".html" || lowerExtension(path) == ".htm";
}

void save(PyGrid& self, const py::object& pathObj, const py::object& facesName, const py::object& colorName,
          const py::object& asciiArg, const py::object& bricksArg, const py::object& threads,
          const py::object& progress) {
  const std::optional<std::string> path = pathArg(pathObj, "path");
  const vox::FaceMode faces = enumArg(facesName, "faces", vox::parseFaceMode);
  const vox::ColorMode color = enumArg(colorName, "color", vox::parseColorMode);
  const bool ascii = boolArg(asciiArg, "ascii");
  const auto nThreads = threadsArg(threads);
  // As the tools: an output that is the grid's own file is refused, a missing folder reported, before any work.
  std::vector<std::string> inputs;
  if (self.source() != "<arrays>") inputs.push_back(self.source());
  const auto voxelFormat = vox::voxelFormatFromPath(*path);
  const bool gridFile = isGridFilePath(*path), page = isViewerPagePath(*path);
  if (page && !vox::viewerPageAvailable()) vox::viewerPageHtml({}, {});  // the build's UsageError, before any work
  if (!gridFile && !voxelFormat && !page) optionArg("path", *path, vox::meshFormatFromPath);
  std::optional<std::array<uint32_t, 3>> bricks;
  if (!bricksArg.is_none()) {
    if (!gridFile) vox::fail<vox::UsageError>("bricks: only a .vgrid output is written as a grid set");
    bricks = dims3Arg(bricksArg, "bricks", UINT32_MAX);
    vox::checkBrickCounts(self.grid().dims, *bricks);
    vox::checkGridSetHolds(self.grid(), "bricks");  // as vox-voxelize refuses --bricks with --sdf or --fraction
  }
  vox::checkOutputPath(*path, inputs);
  if (!gridFile && !voxelFormat && !page && vox::meshFormatFromPath(*path) == vox::MeshFormat::Obj)
    vox::checkOutputPath(std::filesystem::path(*path).replace_extension(".mtl").string(), inputs);

  Interrupt interrupt(progressCallable(progress, "saving"));
  const auto poll = [&](double f) {
    if (!interrupt.poll(f)) vox::fail<vox::Error>("save cancelled");
  };
  vox::VoxelFileReport report;
  runLong(interrupt, nThreads, [&] {
    const vox::Grid& grid = self.grid();
    if (gridFile && bricks) {
      // The grid's own cells, split into bricks: the set read back is the grid (vox-voxelize --bricks voxelizes
      // brick by brick instead, to keep one brick in memory; here the whole grid is in memory already).
      vox::writeGridAsSet(*path, self.scene(), grid, *bricks, [&](double f) { return interrupt.poll(f); });
    } else if (gridFile) {
      vox::writeGridFile(*path, self.scene(), grid, nullptr, [&](double f) { return interrupt.poll(f); });
    } else if (page) {
      vox::ViewerPageOptions options;
      options.color = color;
      options.title = std::filesystem::path(self.source()).filename().string();  // as vox-export: the grid's name
      options.progress = [&](double f) { return interrupt.poll(f); };
      vox::writeViewerPage(*path, grid, self.scene(), options);
    } else if (voxelFormat) {
      std::vector<vox::Rgb8> colors;
      if (*voxelFormat == vox::VoxelFormat::MagicaVoxel && color != vox::ColorMode::None)
        colors =
            vox::occupiedCellColors(grid, self.scene(), color, 0, [&](double f) { return interrupt.poll(0.3 * f); });
      report = vox::writeVoxelFile(*path, *voxelFormat, grid, colors, poll);
    } else {
      const vox::VoxelMesh mesh = vox::buildVoxelMesh(grid, self.scene(), faces, color, nullptr,
                                                      [&](double f) { return interrupt.poll(0.6 * f); });
      poll(0.6);
      vox::writeVoxelMesh(*path, mesh, !ascii, [&](double f) { return interrupt.poll(0.6 + 0.4 * f); });
    }
  });
  if (voxelFormat == vox::VoxelFormat::Binvox && report.binvoxShiftVoxels > 1e-9) {
    // vox-export's numbers (%.9g, %.3g): std::to_string's 6 decimals showed a side of 1e-7 as 0.000000.
    char numbers[2][32];
    std::snprintf(numbers[0], sizeof numbers[0], "%.9g", report.binvoxVoxelSide);
    std::snprintf(numbers[1], sizeof numbers[1], "%.3g", report.binvoxShiftVoxels);
    warn(*path + ": binvox voxels are cubes; the grid's cells are not, so they are written as cubes of side " +
         numbers[0] + " (the longest axis' cell) and the grid's far face moves by up to " + numbers[1] + " voxels");
  }
  if (report.paletteReduced)
    warn(*path + ": " + std::to_string(report.gridColors) + " voxel colours reduced to a palette of " +
         std::to_string(report.paletteColors) + " (median cut)");
}

}  // namespace

void bindSave(GridClass& grid) {
  grid.def("save", &save, py::arg("path"), py::kw_only(), py::arg("faces") = "exposed", py::arg("color") = "count",
           py::arg("ascii") = false, py::arg("bricks") = py::none(), py::arg("threads") = py::none(),
           py::arg("progress") = false, R"doc(
Writes the grid in the format of the path's extension, as vox-voxelize and vox-export write it:
  .vgrid: the grid file with its scene (libvox.load and the tools read it); with bricks=(bx, by, bz), a grid set
      in the layout vox-voxelize --bricks writes, holding the grid's own cells and solid runs split into bricks (a
      set holds no signed distances or volume fractions: a grid with either is refused, UsageError);
  .ply .obj .off .stl .glb .gltf: the voxels as a mesh; faces 'all' (a cube per voxel), 'exposed' (closed,
      2-manifold) or 'merged' (exposed faces merged into rectangles); color 'count', 'material' or 'none';
      ascii=True for ASCII PLY/STL;
  .binvox (cubic voxels, the corner at bounds[0]), .vox (MagicaVoxel; palette from color), .vdb (OpenVDB grids
      'density' and 'count');
  .html: vox-export's viewer page (three.js inside, opens from disk), when the build has it.
Written through a temporary file and a rename: a failure leaves the old file as it was.
Raises UsageError (unknown extension or option, or the grid's own file as output), OSError (cannot write),
LimitError (the format cannot hold the grid, e.g. binvox above 4096 a side).
)doc");
}

}  // namespace voxpy
