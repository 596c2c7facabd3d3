// Grid.save: every output of vox-voxelize and vox-export, by extension, through the same library calls.
#include <filesystem>

#include "binding.h"
#include "vox/core/error.h"
#include "vox/export/voxel_format.h"
#include "vox/export/voxel_mesh.h"
#include "vox/io/atomic_file.h"

namespace voxpy {

namespace {

bool isGridFilePath(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".vgrid";
}

template <class Parse>
auto optionArg(const char* name, const std::string& value, Parse&& parse) {
  try {
    return parse(value);
  } catch (const vox::InputError& e) {
    throw vox::UsageError(std::string(name) + ": " + e.what());
  }
}

void warn(const std::string& message) {
  if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 1) != 0) throw py::error_already_set();
}

void save(PyGrid& self, const py::object& pathObj, const std::string& facesName, const std::string& colorName,
          bool ascii, const py::object& threads, const py::object& progress) {
  const auto path = pathArg(pathObj);
  if (!path) throw py::type_error("path must be a str or os.PathLike");
  const vox::FaceMode faces = optionArg("faces", facesName, vox::parseFaceMode);
  const vox::ColorMode color = optionArg("color", colorName, vox::parseColorMode);
  const auto nThreads = threadsArg(threads);
  // As the tools: an output that is the grid's own file is refused, a missing folder reported, before any work.
  std::vector<std::string> inputs;
  if (self.source() != "<arrays>") inputs.push_back(self.source());
  const auto voxelFormat = vox::voxelFormatFromPath(*path);
  const bool gridFile = isGridFilePath(*path);
  if (!gridFile && !voxelFormat) optionArg("path", *path, vox::meshFormatFromPath);
  vox::checkOutputPath(*path, inputs);
  if (!gridFile && !voxelFormat && vox::meshFormatFromPath(*path) == vox::MeshFormat::Obj)
    vox::checkOutputPath(std::filesystem::path(*path).replace_extension(".mtl").string(), inputs);

  Interrupt interrupt(progressCallable(progress, "saving"));
  const auto poll = [&](double f) {
    if (!interrupt.poll(f)) vox::fail<vox::Error>("save cancelled");
  };
  vox::VoxelFileReport report;
  runLong(interrupt, nThreads, [&] {
    const vox::Grid& grid = self.grid();
    if (gridFile) {
      vox::writeGridFile(*path, self.scene(), grid);
    } else if (voxelFormat) {
      std::vector<vox::Rgb8> colors;
      if (*voxelFormat == vox::VoxelFormat::MagicaVoxel && color != vox::ColorMode::None)
        colors = vox::occupiedCellColors(grid, self.scene(), color);
      report = vox::writeVoxelFile(*path, *voxelFormat, grid, colors, poll);
    } else {
      const vox::VoxelMesh mesh = vox::buildVoxelMesh(grid, self.scene(), faces, color);
      poll(0.6);
      vox::writeVoxelMesh(*path, mesh, !ascii);
    }
  });
  if (voxelFormat == vox::VoxelFormat::Binvox && report.binvoxShiftVoxels > 1e-9)
    warn(*path + ": binvox voxels are cubes; the grid's cells are not, so they are written as cubes of side " +
         std::to_string(report.binvoxVoxelSide) + " (the longest axis' cell) and the grid's far face moves by up to " +
         std::to_string(report.binvoxShiftVoxels) + " voxels");
  if (report.paletteReduced)
    warn(*path + ": " + std::to_string(report.gridColors) + " voxel colours reduced to a palette of " +
         std::to_string(report.paletteColors) + " (median cut)");
}

}  // namespace

void bindSave(GridClass& grid) {
  grid.def("save", &save, py::arg("path"), py::kw_only(), py::arg("faces") = "exposed", py::arg("color") = "count",
           py::arg("ascii") = false, py::arg("threads") = py::none(), py::arg("progress") = false, R"doc(
Writes the grid in the format of the path's extension, as vox-voxelize and vox-export write it:
  .vgrid: the grid file with its scene (libvox.load and the tools read it);
  .ply .obj .off .stl .glb .gltf: the voxels as a mesh; faces 'all' (a cube per voxel), 'exposed' (closed,
      2-manifold) or 'merged' (exposed faces merged into rectangles); color 'count', 'material' or 'none';
      ascii=True for ASCII PLY/STL;
  .binvox (cubic voxels, the corner at bounds[0]), .vox (MagicaVoxel; palette from color), .vdb (OpenVDB grids
      'density' and 'count').
Written through a temporary file and a rename: a failure leaves the old file as it was.
Raises UsageError (unknown extension or option, or the grid's own file as output), OSError (cannot write),
LimitError (the format cannot hold the grid, e.g. binvox above 4096 a side).
)doc");
}

}  // namespace voxpy
