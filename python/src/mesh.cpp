// Grid.mesh and Grid.colors: the voxel mesh and cell colours of vox-export as arrays.
#include "binding.h"
#include "vox/core/error.h"
#include "vox/export/level_surface.h"
#include "vox/export/voxel_mesh.h"

namespace voxpy {

namespace {

// (n, 4) uint8 RGBA (alpha 255) from 8-bit RGB display colours.
py::array_t<uint8_t> rgba(const std::vector<vox::Rgb8>& colors) {
  py::array_t<uint8_t> out({py::ssize_t(colors.size()), py::ssize_t(4)});
  uint8_t* p = out.mutable_data();
  for (size_t n = 0; n < colors.size(); ++n) {
    p[4 * n] = colors[n][0], p[4 * n + 1] = colors[n][1], p[4 * n + 2] = colors[n][2];
    p[4 * n + 3] = 255;
  }
  return out;
}

py::tuple mesh(PyGrid& self, const py::object& facesName, const py::object& colorName, const py::object& threads) {
  const vox::FaceMode faces = enumArg(facesName, "faces", vox::parseFaceMode);
  const vox::ColorMode color = enumArg(colorName, "color", vox::parseColorMode);
  Interrupt interrupt;
  // Ctrl-C looked at as the other long calls do (Interrupt): 1.7 s for the bunny at 512^3 before it was.
  vox::VoxelMesh m = runLong(interrupt, threadsArg(threads), [&] {
    const vox::VoxelMesh polygons = vox::buildVoxelMesh(self.grid(), self.scene(), faces, color, nullptr,
                                                        [&](double f) { return interrupt.poll(0.8 * f); });
    return vox::triangulateVoxelMesh(polygons, [&](double f) { return interrupt.poll(0.8 + 0.2 * f); });
  });
  if (m.vertexCount() > size_t(INT32_MAX)) vox::fail<vox::LimitError>("mesh(): more than 2^31 - 1 vertices");
  const py::ssize_t nv = py::ssize_t(m.vertexCount()), nf = py::ssize_t(m.faceCount());
  py::object colors = m.hasColors() ? py::object(rgba(m.faceColors)) : py::object(py::none());
  static_assert(sizeof(vox::Vec3) == 3 * sizeof(double));
  return py::make_tuple(adoptVector<double>(std::move(m.positions), {nv, 3}),
                        adoptVector<int32_t>(std::move(m.faceVertices), {nf, 3}), colors);
}

py::tuple surface(PyGrid& self, const py::object& level, const py::object& threads) {
  const double lvl = floatArg(level, "level");
  if (self.grid().sdfHalfWidth == 0)
    vox::fail<vox::InputError>(
        "surface(): the grid has no signed distances: voxelize it with sdf=HALF "
        "(vox-voxelize --sdf)");
  Interrupt interrupt;
  vox::VoxelMesh m = runLong(interrupt, threadsArg(threads), [&] {
    return vox::extractLevelSurface(self.grid(), lvl, nullptr, [&](double f) { return interrupt.poll(f); });
  });
  return surfaceArrays(std::move(m));
}

py::array_t<uint8_t> colors(PyGrid& self, const py::object& modeName) {
  const vox::ColorMode mode = enumArg(modeName, "mode", vox::parseColorMode);
  if (mode == vox::ColorMode::None) vox::fail<vox::UsageError>("mode: expected 'count' or 'material'");
  Interrupt interrupt;
  const auto c = runLong(interrupt, std::nullopt, [&] {
    return vox::occupiedCellColors(self.grid(), self.scene(), mode, 0, [&](double f) { return interrupt.poll(f); });
  });
  return rgba(c);
}

}  // namespace

py::tuple surfaceArrays(vox::VoxelMesh&& m) {
  const py::ssize_t nv = py::ssize_t(m.vertexCount()), nf = py::ssize_t(m.faceCount());
  std::vector<int64_t> faces(m.faceVertices.begin(), m.faceVertices.end());
  m.faceVertices = {};
  return py::make_tuple(adoptVector<double>(std::move(m.positions), {nv, 3}),
                        adoptVector<int64_t>(std::move(faces), {nf, 3}));
}

void bindMesh(GridClass& grid) {
  grid.def("surface", &surface, py::arg("level") = 0.0, py::kw_only(), py::arg("threads") = py::none(), R"doc(
The level set d = level (world units; 0 the surface, > 0 grown, < 0 shrunk) of the grid's signed distances
(voxelize(..., sdf=HALF)) as a closed, two-manifold triangle mesh oriented outward, as vox-export --surface writes
it: vertices (V, 3) float64 (world space, one per lattice edge the level crosses, distinct), faces (F, 3) int64,
counter-clockwise seen from outside, none of zero area. Marching tetrahedra over the cell centres of the band;
where the level set leaves the grid it is closed on the grid's bounds. |level| may be at most
HALF * (smallest cell edge) - (cell diagonal). Raises InputError for a grid without distances (naming sdf=) or a
level outside that range, TypeError for a level that is not a number.
)doc");
  grid.def("mesh", &mesh, py::arg("faces") = "merged", py::arg("color") = "none", py::kw_only(),
           py::arg("threads") = py::none(), R"doc(
The voxels (occupied and solid cells) as a triangle mesh, as vox-export builds it: vertices (V, 3) float64 on the
cell lattice (world space), faces (F, 3) int32, counter-clockwise seen from outside, and face_colors (F, 4) uint8
RGBA (sRGB) or None when color='none'. faces: 'all' (12 triangles per voxel), 'exposed' (closed, 2-manifold) or
'merged' (exposed faces merged into rectangles, no T-junctions); color: 'count', 'material' or 'none'.
)doc");
  grid.def("colors", &colors, py::arg("mode") = "material", R"doc(
The display colour of each occupied cell ((N, 4) uint8 RGBA, sRGB, alpha 255, `indices` order), as vox-export paints
it: 'material' (the material held by most of the cell's primitives, textures averaged over the cell) or 'count'
(primitives per cell on the viridis ramp, log scale).
)doc");
}

}  // namespace voxpy
