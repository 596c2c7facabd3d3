// libvox.Grid and libvox.load: a grid and its scene, read as numpy arrays (DESIGN.md "Python", "Grid").
#include <algorithm>
#include <sstream>

#include "binding.h"
#include "vox/core/error.h"
#include "vox/export/voxel_runs.h"
#include "vox/io/grid_set.h"
#include "vox/io/input_file.h"

namespace voxpy {

PyGrid::PyGrid(vox::GridFile file, std::string source)
    : file_(std::make_shared<const vox::GridFile>(std::move(file))), source_(std::move(source)) {}

const vox::Accel& PyGrid::accel() {
  return accel_.get([&] { return vox::buildAccel(file_->scene, file_->grid, vox::AccelKind::Grid); });
}

const vox::NearestPrimitive& PyGrid::nearest() {
  return nearest_.get([&] { return vox::NearestPrimitive(file_->scene, vox::sceneFrame(file_->scene)); });
}

const vox::InsideTest& PyGrid::insideTest() {
  return insideTest_.get([&] { return vox::InsideTest(file_->scene, vox::sceneFrame(file_->scene)); });
}

namespace {

using vox::Grid;

double pitchOf(const Grid& g, int a) { return (g.bounds.hi[a] - g.bounds.lo[a]) / double(g.dims[a]); }

// Checks that an array of `bytes` fits the memory budget before it is allocated (LimitError naming the grid).
void checkArray(const PyGrid& grid, double bytes, const char* what) { vox::checkMemory(bytes, grid.source(), what); }

py::array_t<int32_t> indicesOf(const Grid& g, std::span<const uint64_t> keys) {
  py::array_t<int32_t> out({py::ssize_t(keys.size()), py::ssize_t(3)});
  int32_t* p = out.mutable_data();
  for (size_t c = 0; c < keys.size(); ++c) {
    const auto ijk = vox::cellIndex(g.dims, keys[c]);
    for (int a = 0; a < 3; ++a) p[3 * c + a] = int32_t(ijk[a]);
  }
  return out;
}

// The --sdf band: (indices (B, 3) int32 [i, j, k] in ascending key, values (B,) float64); empty arrays without one.
py::tuple sdfBand(PyGrid& self) {
  const Grid& g = self.grid();
  const size_t n = g.sdfKeys.size();
  checkArray(self, double(n) * 20, "sdf");
  py::array_t<int32_t> indices({py::ssize_t(n), py::ssize_t(3)});
  py::array_t<double> values{py::ssize_t(n)};
  int32_t* p = indices.mutable_data();
  double* v = values.mutable_data();
  {
    py::gil_scoped_release release;
    for (size_t b = 0; b < n; ++b, p += 3) {
      const auto ijk = vox::cellIndex(g.dims, g.sdfKeys[b]);
      p[0] = int32_t(ijk[0]), p[1] = int32_t(ijk[1]), p[2] = int32_t(ijk[2]);
      v[b] = g.sdfValues[b];
    }
  }
  return py::make_tuple(indices, values);
}

// The --fraction values: (N,) float64 in the order of `indices`; an empty array without them.
py::array_t<double> fractions(PyGrid& self) {
  const Grid& g = self.grid();
  checkArray(self, double(g.fractions.size()) * 8, "fractions");
  py::array_t<double> out{py::ssize_t(g.fractions.size())};
  std::copy(g.fractions.begin(), g.fractions.end(), out.mutable_data());
  return out;
}

py::array_t<int32_t> solidIndices(PyGrid& self) {
  const Grid& g = self.grid();
  const uint64_t n = g.solidCount();
  checkArray(self, double(n) * 12, "solid_indices");
  py::array_t<int32_t> out({py::ssize_t(n), py::ssize_t(3)});
  int32_t* p = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (const vox::CellRun& r : g.solidRuns)
      for (uint64_t key = r.first; key < r.first + r.count; ++key, p += 3) {
        const auto ijk = vox::cellIndex(g.dims, key);
        p[0] = int32_t(ijk[0]), p[1] = int32_t(ijk[1]), p[2] = int32_t(ijk[2]);
      }
  }
  return out;
}

py::array_t<bool> dense(PyGrid& self, const py::object& solidArg) {
  const bool solid = boolArg(solidArg, "solid");
  const Grid& g = self.grid();
  checkArray(self, double(g.cellCount()), "dense()");
  const auto [nx, ny, nz] = g.dims;
  py::array_t<bool> out({py::ssize_t(nx), py::ssize_t(ny), py::ssize_t(nz)});
  bool* p = out.mutable_data();
  {
    py::gil_scoped_release release;
    std::fill(p, p + g.cellCount(), false);
    // Index [i, j, k] of a C-ordered (nx, ny, nz) array; a voxel row runs along i.
    const uint64_t strideI = uint64_t(ny) * nz;
    auto mark = [&](const vox::VoxelRow& r) {
      bool* q = p + uint64_t(r.i0) * strideI + uint64_t(r.j) * nz + r.k;
      for (uint32_t n = 0; n < r.count; ++n) q[n * strideI] = true;
    };
    if (solid) {
      vox::forEachVoxelRow(g, mark);
    } else {
      for (uint64_t key : g.cellKeys) {
        const auto ijk = vox::cellIndex(g.dims, key);
        p[uint64_t(ijk[0]) * strideI + uint64_t(ijk[1]) * nz + ijk[2]] = true;
      }
    }
  }
  return out;
}

py::array_t<double> points(const PyGrid& self) {
  const Grid& g = self.grid();
  py::array_t<double> out({py::ssize_t(g.occupiedCount()), py::ssize_t(3)});
  double* p = out.mutable_data();
  for (size_t c = 0; c < g.occupiedCount(); ++c) {
    const auto ijk = vox::cellIndex(g.dims, g.cellKeys[c]);
    for (int a = 0; a < 3; ++a) p[3 * c + a] = vox::cellCentreOnAxis(g.bounds, g.dims, a, ijk[a]);
  }
  return out;
}

py::array_t<int32_t> counts(const PyGrid& self) {
  const Grid& g = self.grid();
  py::array_t<int32_t> out(py::ssize_t(g.occupiedCount()));
  int32_t* p = out.mutable_data();
  for (size_t c = 0; c < g.occupiedCount(); ++c) p[c] = int32_t(g.cellStart[c + 1] - g.cellStart[c]);
  return out;
}

py::array_t<bool> contains(PyGrid& self, const py::handle& query) {
  const std::vector<vox::Vec3> q = vec3Array(query, "points", true);
  py::array_t<bool> out(py::ssize_t(q.size()));
  bool* p = out.mutable_data();
  const Grid& g = self.grid();
  py::gil_scoped_release release;
  for (size_t n = 0; n < q.size(); ++n) {
    // The closed cells holding the point: two on an axis where it lies on a boundary.
    std::array<std::array<int64_t, 2>, 3> range;
    bool inside = true;
    for (int a = 0; a < 3; ++a) {
      range[a] = vox::cellRange(g.bounds, g.dims, a, q[n][a], q[n][a]);
      inside = inside && range[a][0] <= range[a][1];
    }
    bool hit = false;
    for (int64_t k = range[2][0]; inside && !hit && k <= range[2][1]; ++k)
      for (int64_t j = range[1][0]; !hit && j <= range[1][1]; ++j)
        for (int64_t i = range[0][0]; !hit && i <= range[0][1]; ++i) {
          const uint64_t key = vox::cellKey(g.dims, i, j, k);
          hit = vox::findCell(g, key) >= 0 || vox::isSolid(g, key);
        }
    p[n] = hit;
  }
  return out;
}

std::string repr(const PyGrid& self) {
  const Grid& g = self.grid();
  std::ostringstream out;
  out << "<libvox.Grid " << g.dims[0] << "x" << g.dims[1] << "x" << g.dims[2] << " " << vox::methodName(g.method)
      << ", " << g.occupiedCount() << " occupied";
  if (!g.solidRuns.empty()) out << ", " << g.solidCount() << " solid";
  out << " cells, " << self.scene().primitiveCount() << " primitives>";
  return out.str();
}

// Pickling (Grid.__getstate__): the state is (bytes of the grid file, source), the bytes being exactly what
// grid.save("x.vgrid") writes (vox::encodeGridFile: the scene, the cells, the solid runs and every optional section),
// so a grid sent to another process or machine is the same grid cell for cell and primitive for primitive.
// Grid.source as Python shows it: a path as os.fsdecode gives it (a name that is not UTF-8 round-trips).
py::str sourceText(const PyGrid& self) {
  return self.source() == "<arrays>" ? py::str(self.source()) : pathText(self.source());
}

py::object getState(const PyGrid& self) {
  Interrupt interrupt;  // Ctrl-C while a large grid is encoded
  const std::string bytes = runLong(interrupt, std::nullopt, [&] {
    vox::checkGridBeforeWrite(self.grid(), self.source());  // no pickle that unpickling refuses
    return vox::encodeGridFile(self.scene(), self.grid(), 0, [&](double f) { return interrupt.poll(f); });
  });
  return py::make_tuple(py::bytes(bytes), sourceText(self));
}

// A Grid from the state of a pickle (libvox._unpickle_grid, the reconstructor Grid.__reduce__ names): decodes the
// bytes with every check libvox.load makes (counts, offsets, ids, checksum), so a truncated or corrupt pickle raises
// InputError; a state that is not (bytes, str) raises TypeError saying which part is wrong.
std::shared_ptr<PyGrid> fromState(const py::handle& state) {
  constexpr const char* kWhat = "pickled libvox.Grid: the state must be (grid file bytes, source str)";
  if (!py::isinstance<py::tuple>(state)) failType(kWhat, ", not ", typeName(state));
  const auto items = py::reinterpret_borrow<py::tuple>(state);
  if (items.size() != 2) failType(kWhat, ", got a tuple of ", items.size(), " items");
  if (!py::isinstance<py::bytes>(items[0])) failType(kWhat, ": its first item is ", typeName(items[0]), ", not bytes");
  if (!py::isinstance<py::str>(items[1])) failType(kWhat, ": its second item is ", typeName(items[1]), ", not str");
  const std::string bytes = items[0].cast<std::string>();
  const py::object sourceObj = items[1];
  const std::string source = sourceObj.equal(py::str("<arrays>")) ? "<arrays>" : pathArg(sourceObj, "source");
  Interrupt interrupt;
  vox::GridFile file = runLong(interrupt, std::nullopt, [&] {
    return vox::decodeGridFile(bytes, "pickled grid (" + source + ")", [&](double f) { return interrupt.poll(f); });
  });
  return std::make_shared<PyGrid>(std::move(file), source);
}

// Grid.__setstate__: a Grid is read-only and complete from the moment it exists (unpickling makes a new one through
// libvox._unpickle_grid), so setting a state is refused, the grid left as it was, instead of pybind11's silent
// no-op on an initialised instance.
void setStateRefused(const PyGrid&, const py::handle&) {
  failType(
      "libvox.Grid.__setstate__: this Grid is already initialised and grids are read-only; pickle.loads "
      "makes a new Grid from a state");
}

}  // namespace

void checkInitialised(const py::handle& obj) {
  const py::detail::type_info* info = py::detail::get_type_info(typeid(PyGrid));
  if (!info || !PyObject_TypeCheck(obj.ptr(), info->type)) return;
  auto* instance = reinterpret_cast<py::detail::instance*>(obj.ptr());
  if (!instance->get_value_and_holder(info).holder_constructed())
    failType(
        "libvox.Grid: this object was made by __new__ alone and holds no grid; grids come from "
        "libvox.voxelize, libvox.voxelize_batch, libvox.load and pickle.loads");
}

namespace {

py::object refuseNew(const py::handle&, const py::args&, const py::kwargs&) {
  failType(
      "libvox.Grid cannot be made directly: grids come from libvox.voxelize, libvox.voxelize_batch, "
      "libvox.load and pickle.loads");
}

}  // namespace

GridClass bindGrid(py::module_& m) {
  GridClass grid(m, "Grid", R"doc(
A sparse voxel grid and the scene it was voxelized from (read-only).

Conventions: world coordinates are float64; cell indices are int32 [i, j, k] along x, y, z. Cell (i, j, k) is the
closed box whose bounds on axis a are b_a(i) and b_a(i+1), b_a(i) = lo_a + (hi_a - lo_a) * i / n_a (double
precision); its centre is the midpoint. A primitive touching a cell's face, edge or corner belongs to that cell.
Occupied cells hold primitives; solid cells (voxelize(..., fill=True)) are empty cells inside closed surfaces.

Made by libvox.voxelize, libvox.voxelize_batch(..., dense=False) and libvox.load; written by Grid.save.
Pickles (multiprocessing, concurrent.futures, Dask) as the bytes of its grid file, the same bytes Grid.save writes
to a .vgrid, with its source; unpickling checks them as libvox.load does (InputError for corrupt bytes).
Arrays returned by properties are computed on each access unless noted (keep the result in a loop).
)doc");
  grid.def_property_readonly(
          "dims", [](const PyGrid& s) { return py::make_tuple(s.grid().dims[0], s.grid().dims[1], s.grid().dims[2]); },
          "Cells per axis (nx, ny, nz), a tuple of ints.")
      .def_property_readonly(
          "bounds",
          [](const PyGrid& s) {
            const vox::Box& b = s.grid().bounds;
            py::array_t<double> out({2, 3});
            double* p = out.mutable_data();
            for (int a = 0; a < 3; ++a) p[a] = b.lo[a], p[3 + a] = b.hi[a];
            return out;
          },
          "World bounds of the grid, (2, 3) float64: [[x0, y0, z0], [x1, y1, z1]].")
      .def_property_readonly(
          "pitch",
          [](const PyGrid& s) {
            py::array_t<double> out(3);
            for (int a = 0; a < 3; ++a) out.mutable_data()[a] = pitchOf(s.grid(), a);
            return out;
          },
          "Cell edge lengths (3,) float64: (hi - lo) / dims per axis.")
      .def_property_readonly(
          "transform",
          [](const PyGrid& s) {
            py::array_t<double> out({4, 4});
            double* p = out.mutable_data();
            std::fill(p, p + 16, 0.0);
            for (int a = 0; a < 3; ++a) {
              const double pitch = pitchOf(s.grid(), a);
              p[4 * a + a] = pitch;
              p[4 * a + 3] = s.grid().bounds.lo[a] + 0.5 * pitch;
            }
            p[15] = 1;
            return out;
          },
          "(4, 4) float64 mapping [i, j, k, 1] to the cell centre [x, y, z, 1] (column vectors): diag(pitch), "
          "translation lo + pitch / 2. Equal to `points` up to rounding; `points` are the exact midpoints.")
      .def_property_readonly(
          "method", [](const PyGrid& s) { return vox::methodName(s.grid().method); },
          "Overlap method the grid was made with: 'exact', 'sat', 'bbox' or 'center'.")
      .def_property_readonly(
          "occupied_count", [](const PyGrid& s) { return s.grid().occupiedCount(); }, "Number of occupied cells N.")
      .def_property_readonly(
          "solid_count", [](const PyGrid& s) { return s.grid().solidCount(); },
          "Number of solid cells M (0 without fill).")
      .def_property_readonly(
          "primitive_count", [](const PyGrid& s) { return s.scene().primitiveCount(); },
          "Primitives of the scene: triangles, then spheres, then planes (their ids).")
      .def_property_readonly(
          "indices", [](const PyGrid& s) { return indicesOf(s.grid(), s.grid().cellKeys); },
          "Occupied cells, (N, 3) int32 [i, j, k], in the file's order (ascending key i + nx (j + ny k)).")
      .def_property_readonly("fractions", &fractions,
                             "The volume fractions of voxelize(..., fraction=True): (N,) float64 in [0, 1], the part "
                             "of each occupied cell (the order of indices) inside the solid; solid cells count 1. "
                             "Empty without them.")
      .def_property_readonly("sdf", &sdfBand,
                             "The signed distance band of voxelize(..., sdf=HALF): (indices (B, 3) int32 [i, j, k], "
                             "ascending key; values (B,) float64, negative inside). Empty arrays without one.")
      .def_property_readonly(
          "sdf_half_width", [](PyGrid& self) { return self.grid().sdfHalfWidth; },
          "The band's half-width in smallest cell edges (0.0 without distances).")
      .def_property_readonly("solid_indices", &solidIndices,
                             "Solid cells (fill), (M, 3) int32 [i, j, k], ascending key. Empty without fill. "
                             "LimitError when they would not fit in memory.")
      .def("dense", &dense, py::arg("solid") = true, R"doc(
The grid as a dense np.bool_ array of shape dims, indexed [i, j, k] (C order). True for occupied cells, and for
solid cells too when `solid`. LimitError when nx*ny*nz bytes exceed the memory budget.
)doc")
      .def_property_readonly("points", &points, "Centres of the occupied cells, (N, 3) float64, in `indices` order.")
      .def_property_readonly("counts", &counts, "Primitives held by each occupied cell, (N,) int32.")
      .def_property_readonly(
          "cell_primitives",
          [](const py::object& self) {
            const Grid& g = self.cast<PyGrid&>().grid();
            static_assert(sizeof(uint64_t) == sizeof(int64_t));
            return py::make_tuple(readOnlyView(reinterpret_cast<const int64_t*>(g.cellStart.data()),
                                               {py::ssize_t(g.cellStart.size())}, self),
                                  readOnlyView(g.primIds.data(), {py::ssize_t(g.primIds.size())}, self));
          },
          "(offsets, ids): the primitive ids of occupied cell c are ids[offsets[c]:offsets[c + 1]], ascending. "
          "offsets (N + 1,) int64, ids (R,) uint32; read-only views of the grid's memory (no copy).")
      .def("contains", &contains, py::arg("points"), R"doc(
For each point of `points` ((P, 3) float), whether a closed cell holding it is occupied or solid: (P,) bool. A point
on a boundary between cells counts for both; points outside the bounds are False.
)doc")
      .def_property_readonly("source", &sourceText,
                             "Where the grid came from: a file path (as os.fsdecode gives it), or '<arrays>'.")
      .def("__repr__", &repr)
      // Grid.__new__ refuses: an instance without its C++ object (what Grid.__new__(Grid) or a pickle stream that
      // stops after it made) must not exist. Pickles (every protocol, copy.copy, copy.deepcopy) call
      // libvox._unpickle_grid(state) instead, which makes the Grid whole or raises.
      .def_static("__new__", &refuseNew)
      .def("__getstate__", &getState,
           "The pickle state: (bytes of the grid file, as Grid.save writes a .vgrid; source).")
      .def("__setstate__", &setStateRefused, py::arg("state"),
           "Refused with TypeError: a Grid is read-only once made (pickle.loads makes a new one).")
      .def("__reduce__", [](const PyGrid& self) {
        return py::make_tuple(py::module_::import("libvox").attr("_unpickle_grid"), py::make_tuple(getState(self)));
      });
  // pybind11 2.10 takes every method named __setstate__ for a constructor, which its dispatcher skips without a word
  // on an initialised instance (issue 45: it did nothing and raised nothing): this one is a plain method.
  functionRecord(py::detail::get_function(grid.attr("__setstate__")))->is_constructor = false;
  m.def("_grid_from_state", &fromState, py::arg("state"),
        "The Grid of a pickle state (libvox._unpickle_grid calls it): InputError for corrupt bytes, TypeError for a "
        "state that is not (bytes, str).");

  m.def(
      "load",
      [](const py::object& path) {
        const std::string p = pathArg(path, "path");
        Interrupt interrupt;
        vox::GridFile file = runLong(interrupt, std::nullopt, [&] {
          return vox::readGridOrSet(p, [&](double f) { return interrupt.poll(f); });
        });
        return std::make_shared<PyGrid>(std::move(file), p);
      },
      py::arg("path"), R"doc(
Reads a grid file (.vgrid, vox-voxelize's output) or a grid set (vox-voxelize --bricks) with its scene. Every count,
offset and the checksum are checked: InputError naming the file and the byte offset for a truncated, corrupt or
newer-version file; LimitError when it cannot fit in memory.
)doc");
  return grid;
}

}  // namespace voxpy
