// libvox.voxelize and libvox.voxelize_batch: a scene file or arrays in, a Grid or dense arrays out, as vox-voxelize
// makes them (the same library calls in the same order: loadScene, voxelizeScene, fillSolid).
#include <tbb/parallel_for.h>

#include <cmath>

#include "binding.h"
#include "vox/core/exact_number.h"
#include "vox/core/error.h"
#include "vox/export/voxel_runs.h"
#include "vox/import/import.h"
#include "vox/io/input_file.h"
#include "vox/core/memory_budget.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/export/level_surface.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace voxpy {

namespace {

// A voxelize source: a scene file to read (with the GIL released), or a scene made from arrays.
struct Source {
  std::optional<std::string> path;  // file system bytes
  vox::Scene scene;
  std::string name;   // the path, or "<arrays>"
  std::string label;  // what messages start with: "" for voxelize's source, "sources[i]: " in a batch

  // `poll`: Interrupt::poll, asked while the importer parses (a few hundred MB of OBJ take seconds).
  const vox::Scene& load(const std::function<bool(double)>& poll) {
    if (path) {
      scene = vox::loadScene(*path, poll);
      path.reset();
    }
    return scene;
  }
  // A message about this source: the label, then the path unless the message names it already (the importers'
  // messages and warnings start with it), so that no message says the path twice.
  std::string describe(const std::string& message) const {
    if (message.rfind(name, 0) == 0) return label + message;  // "<arrays>: " too (checkMemory names it)
    if (name == "<arrays>" && !label.empty()) return label + message;
    return label + name + ": " + message;
  }
};

// obj.<attr>, or a null object when it has none; any other exception of the attribute (a property that raises)
// propagates as it is.
py::object attrOrNull(const py::handle& obj, const char* attr) {
  PyObject* value = PyObject_GetAttrString(obj.ptr(), attr);
  if (value) return py::reinterpret_steal<py::object>(value);
  if (!PyErr_ExceptionMatches(PyExc_AttributeError)) throw py::error_already_set();
  PyErr_Clear();
  return py::object();
}

// A scene from arrays, its InputError and LimitError prefixed with the label (a batch says which source).
vox::Scene arraysScene(const py::handle& vertices, const py::handle& faces, const std::string& label) {
  try {
    return sceneFromArrays(vertices, faces);
  } catch (const vox::InputError& e) {
    if (label.empty()) throw;
    throw vox::InputError(label + e.what());
  } catch (const vox::LimitError& e) {
    if (label.empty()) throw;
    throw vox::LimitError(label + e.what());
  }
}

// `what` names the argument in messages ("source", "sources[3]"); `label` as Source::label.
Source sourceArg(const py::handle& obj, const std::string& what, const std::string& label) {
  Source s;
  s.name = "<arrays>";
  s.label = label;
  if ((py::isinstance<py::tuple>(obj) || py::isinstance<py::list>(obj)) && py::len(obj) == 2) {
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(obj);
    s.scene = arraysScene(pair[0], pair[1], label);
    return s;
  }
  if (isPath(obj)) {
    s.path = pathArg(obj, what);
    s.name = *s.path;
    const std::string& p = *s.path;
    if (p.size() > 6 && p.compare(p.size() - 6, 6, ".vgrid") == 0)
      vox::fail<vox::UsageError>(label, p, ": a grid file, not a scene: libvox.load reads it");
    return s;
  }
  const py::object vertices = attrOrNull(obj, "vertices");
  const py::object faces = vertices ? attrOrNull(obj, "faces") : py::object();
  if (!vertices || !faces)
    failType(what, " must be a path, a (vertices, faces) pair or an object with .vertices and .faces, not ",
             typeName(obj));
  s.scene = arraysScene(vertices, faces, label);
  return s;
}

bool fillArg(const py::object& fill) { return boolArg(fill, "fill", true); }

// pitch: cells of that edge length (per axis when three numbers): dims = ceil(extent / pitch), the bounds grown
// symmetrically to whole cells (DESIGN.md "Python").
struct Pitch {
  vox::Vec3 size;
};

void applyPitch(const Pitch& pitch, const vox::Scene& scene, vox::VoxelizeOptions& vo) {
  std::optional<vox::Box> extent = vo.bounds;
  if (!extent) extent = vox::sceneBounds(scene);
  if (!extent) return;  // no bounded primitive: planGrid's empty 1x1x1 grid
  vox::Box b = *extent;
  std::array<uint32_t, 3> dims{};
  for (int a = 0; a < 3; ++a) {
    const double p = pitch.size[a], lo = b.lo[a], hi = b.hi[a];
    const double cells = std::ceil((hi - lo) / p);
    if (!(cells <= vox::kMaxCellsPerAxis))
      vox::fail<vox::UsageError>("pitch ", p, " gives ", cells, " cells on axis ", "xyz"[a], ", more than ",
                                 vox::kMaxCellsPerAxis);
    dims[a] = std::max<uint32_t>(1, uint32_t(cells));
    const double mid = 0.5 * (lo + hi), half = 0.5 * dims[a] * p;
    b.lo.at(a) = std::min(lo, mid - half);  // min/max: never cut the extent by a rounding
    b.hi.at(a) = std::max(hi, mid + half);
  }
  vo.bounds = b;
  vo.dims = dims;
}

// The library's errors of a voxelization named with the source, as vox-voxelize names them: LimitError and
// InputError always, UsageError too in a batch (where the options are the same for every source and a failing
// plan is the source's).
template <class Work>
auto namedAfter(const Source& src, Work&& work) -> decltype(work()) {
  try {
    return work();
  } catch (const vox::LimitError& e) {
    throw vox::LimitError(src.describe(e.what()));
  } catch (const vox::InputError& e) {
    throw vox::InputError(src.describe(e.what()));
  } catch (const vox::UsageError& e) {
    if (src.label.empty()) throw;
    throw vox::UsageError(src.label + e.what());
  }
}

// pitch: one positive number, or three.
vox::Vec3 pitchArg(const py::object& pitch) {
  const vox::Vec3 size = isSequence(pitch) ? vec3Arg(pitch, "pitch") : vox::Vec3{1, 1, 1} * floatArg(pitch, "pitch");
  for (int a = 0; a < 3; ++a)
    if (!(size[a] > 0)) vox::fail<vox::UsageError>("pitch must be positive, got ", vox::exactNumber(size[a]));
  return size;
}

// The grid a call asks for: at most one of resolution, dims and pitch, bounds, and the method.
struct GridRequest {
  vox::VoxelizeOptions options;
  std::optional<Pitch> pitch;  // applied once the scene is loaded (applyPitch)
};

GridRequest gridRequest(const py::object& resolution, const py::object& dims, const py::object& pitch,
                        const py::object& bounds, const py::object& method) {
  GridRequest r;
  vox::VoxelizeOptions& vo = r.options;
  vo.method = enumArg(method, "method", vox::parseMethod);
  const int given = int(!resolution.is_none()) + int(!dims.is_none()) + int(!pitch.is_none());
  if (given > 1) vox::fail<vox::UsageError>("give at most one of resolution, dims and pitch");
  if (!resolution.is_none()) vo.resolution = uint32_t(intArg(resolution, "resolution", 1, vox::kMaxCellsPerAxis));
  if (!dims.is_none()) vo.dims = dims3Arg(dims, "dims", vox::kMaxCellsPerAxis);
  if (!bounds.is_none()) vo.bounds = boxArg(bounds, "bounds");
  if (!pitch.is_none()) r.pitch = Pitch{pitchArg(pitch)};
  vo.memoryLimitBytes = memoryBudget();
  return r;
}

std::shared_ptr<PyGrid> voxelize(const py::object& source, const py::object& resolution, const py::object& dims,
                                 const py::object& pitch, const py::object& bounds, const py::object& method,
                                 const py::object& fill, const py::object& sdf, const py::object& fraction,
                                 const py::object& threads, const py::object& progress) {
  Source src = sourceArg(source, "source", "");
  GridRequest request = gridRequest(resolution, dims, pitch, bounds, method);
  vox::VoxelizeOptions& vo = request.options;
  const bool doFractions = boolArg(fraction, "fraction", true);
  const bool doFill = fillArg(fill) || doFractions;  // a fraction's cells inside are the fill's solid cells
  std::optional<double> sdfHalfWidth;
  if (!sdf.is_none()) {
    sdfHalfWidth = floatArg(sdf, "sdf");
    vox::checkSdfHalfWidth(*sdfHalfWidth, "sdf");
  }
  const auto nThreads = threadsArg(threads);
  Interrupt interrupt(progressCallable(progress, "voxelizing"));
  const double voxelizeShare = sdfHalfWidth || doFractions ? 0.3 : (doFill ? 0.7 : 1.0);
  const double sdfEnd = doFractions ? 0.6 : 1.0;
  vo.progress = [&](double f) { return interrupt.poll(voxelizeShare * f); };
  vox::FillReport report;
  vox::Grid grid = runLong(interrupt, nThreads, [&] {
    const vox::Scene& scene = src.load([&](double) { return interrupt.poll(0); });
    if (request.pitch) applyPitch(*request.pitch, scene, vo);
    return namedAfter(src, [&] {
      if (sdfHalfWidth) vo = vox::withCubicCells(scene, vo);  // as vox-voxelize --sdf: a level set's cubic cells
      if (doFractions) vox::checkVolumeFractionsPossible(scene, vo.method, vo.memoryLimitBytes);
      vox::checkNumericDomainOfPlan(scene, vo, sdfHalfWidth.has_value(), doFractions);  // before any work
      vox::Grid g = vox::voxelizeScene(scene, vo);
      if (doFill) {
        vox::FillOptions fo;
        fo.memoryLimitBytes = vo.memoryLimitBytes;
        fo.progress = [&](double f) { return interrupt.poll(voxelizeShare + (1 - voxelizeShare) * f); };
        report = vox::fillSolid(g, scene, doFractions ? vox::fillForFractions(fo) : fo);
      }
      if (sdfHalfWidth) {
        vox::SdfOptions so;
        so.halfWidth = *sdfHalfWidth;
        so.memoryLimitBytes = vo.memoryLimitBytes;
        so.progress = [&](double f) { return interrupt.poll(0.3 + (sdfEnd - 0.3) * f); };
        vox::storeSignedDistances(g, scene, so, doFill);
      }
      if (doFractions) {
        vox::FractionOptions fo;
        fo.memoryLimitBytes = vo.memoryLimitBytes;
        const double start = sdfHalfWidth ? sdfEnd : 0.3;
        fo.progress = [&](double f) { return interrupt.poll(start + (1 - start) * f); };
        g.fractions = vox::volumeFractions(g, scene, fo);
      }
      return g;
    });
  });
  for (const std::string& w : src.scene.warnings) warn(src.describe(w));
  if (sdfHalfWidth && !src.scene.planes.empty())
    warn(src.describe(std::to_string(src.scene.planes.size()) + " planes are left out of the signed distances"));
  if (doFill)
    if (const std::string w = vox::fillWarning(report); !w.empty()) warn(src.describe("fill: " + w));
  return std::make_shared<PyGrid>(vox::GridFile{std::move(src.scene), std::move(grid)}, src.name);
}

// libvox.sdf: the signed distance at every cell centre of the grid voxelize(source, ..., sdf=HALF) makes (cubic
// cells with a resolution), as a C-ordered (nx, ny, nz) float64 array; the grid's band values equal it where both
// exist.
py::array_t<double> denseSdf(const py::object& source, const py::object& resolution, const py::object& dims,
                             const py::object& pitch, const py::object& bounds, const py::object& threads,
                             const py::object& progress) {
  Source src = sourceArg(source, "source", "");
  GridRequest request = gridRequest(resolution, dims, pitch, bounds, py::str("exact"));
  vox::VoxelizeOptions& vo = request.options;
  const auto nThreads = threadsArg(threads);
  Interrupt interrupt(progressCallable(progress, "distances"));
  vo.progress = [&](double f) { return interrupt.poll(0.2 * f); };
  std::array<uint32_t, 3> gridDims{};
  std::vector<double> field = runLong(interrupt, nThreads, [&] {
    const vox::Scene& scene = src.load([&](double) { return interrupt.poll(0); });
    if (request.pitch) applyPitch(*request.pitch, scene, vo);
    return namedAfter(src, [&] {
      vo = vox::withCubicCells(scene, vo);
      // The dense array is refused before any work: the plan alone gives its size.
      vox::checkMemory(double(vox::planGrid(scene, vo).cellCount()) * 8, src.name, "sdf()");
      vox::checkNumericDomainOfPlan(scene, vo, true, false);
      vox::Grid g = vox::voxelizeScene(scene, vo);
      std::vector<double> out(g.cellCount());  // signed by InsideTest: no fill needed
      const auto [nx, ny, nz] = g.dims;
      vox::DistanceQueryOptions qo;
      qo.progress = [&](double f) { return interrupt.poll(0.4 + 0.6 * f); };
      vox::denseSignedDistances(g, scene, out, {uint64_t(ny) * nz, nz, 1}, qo);
      gridDims = g.dims;
      return out;
    });
  });
  if (!src.scene.planes.empty())
    warn(src.describe(std::to_string(src.scene.planes.size()) + " planes are left out of the signed distances"));
  return adoptVector<double>(std::move(field), {gridDims[0], gridDims[1], gridDims[2]});
}

// The cube of `resolution` cells a side that voxelize_batch gives a mesh: its longest axis exactly, the others
// centred on the mesh; a mesh of one point gets the unit cube around it (planGrid pads it the same way).
vox::Box batchCube(const vox::Box& b) {
  const vox::Vec3 extent = b.hi - b.lo;
  int longest = 0;
  for (int a = 1; a < 3; ++a)
    if (extent[a] > extent[longest]) longest = a;
  const double side = extent[longest] > 0 ? extent[longest] : 1.0;
  vox::Box cube;
  for (int a = 0; a < 3; ++a) {
    if (a == longest && extent[a] > 0) {
      cube.lo.at(a) = b.lo[a];
      cube.hi.at(a) = b.hi[a];
    } else {
      const double mid = 0.5 * (b.lo[a] + b.hi[a]);
      cube.lo.at(a) = std::min(b.lo[a], mid - 0.5 * side);
      cube.hi.at(a) = std::max(b.hi[a], mid + 0.5 * side);
    }
  }
  return cube;
}

// The sources of a batch: an iterable of sources, not one source (a str would be iterated letter by letter).
// Converting many arrays takes a while with the GIL held: Ctrl-C is looked at after each.
std::vector<Source> sourcesArg(const py::object& sources) {
  constexpr const char* kWhat =
      "sources must be a list of sources (paths, (vertices, faces) pairs or objects with .vertices and .faces), not ";
  if (isPath(sources)) failType(kWhat, typeName(sources), " (for one source: voxelize_batch([source], ...))");
  PyObject* iter = PyObject_GetIter(sources.ptr());
  if (!iter) {
    if (!PyErr_ExceptionMatches(PyExc_TypeError)) throw py::error_already_set();
    PyErr_Clear();
    failType(kWhat, typeName(sources));
  }
  const py::object it = py::reinterpret_steal<py::object>(iter);
  std::vector<Source> srcs;
  while (PyObject* item = PyIter_Next(it.ptr())) {
    const py::object s = py::reinterpret_steal<py::object>(item);
    const std::string what = "sources[" + std::to_string(srcs.size()) + "]";
    srcs.push_back(sourceArg(s, what, what + ": "));
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
  if (PyErr_Occurred()) throw py::error_already_set();
  return srcs;
}

py::object voxelizeBatch(const py::object& sources, const py::object& resolution, const py::object& fill,
                         const py::object& method, const py::object& threads, const py::object& denseArg,
                         const py::object& progress) {
  std::vector<Source> srcs = sourcesArg(sources);
  const uint32_t r = uint32_t(intArg(resolution, "resolution", 1, vox::kMaxCellsPerAxis));
  const vox::OverlapMethod m = enumArg(method, "method", vox::parseMethod);
  const bool doFill = fillArg(fill);
  const bool dense = boolArg(denseArg, "dense");
  const auto nThreads = threadsArg(threads);
  const uint64_t budget = memoryBudget();
  const uint64_t cube = uint64_t(r) * r * r;
  py::array_t<bool> out;
  bool* cells = nullptr;
  if (dense) {
    vox::checkMemory(double(cube) * double(srcs.size()), "voxelize_batch", "the dense array");
    out = py::array_t<bool>({py::ssize_t(srcs.size()), py::ssize_t(r), py::ssize_t(r), py::ssize_t(r)});
    cells = out.mutable_data();
  }
  std::vector<vox::Grid> grids(dense ? 0 : srcs.size());
  std::vector<vox::FillReport> reports(srcs.size());
  Interrupt interrupt(progressCallable(progress, "voxelizing"));
  std::atomic<size_t> done{0};
  runLong(interrupt, nThreads, [&] {
    tbb::parallel_for(size_t(0), srcs.size(), [&](size_t b) {
      if (interrupt.cancelled()) return;
      Source& src = srcs[b];
      vox::Grid g = namedAfter(src, [&] {
        const vox::Scene& scene =
            src.load([&](double) { return interrupt.poll(double(done.load()) / double(srcs.size())); });
        vox::VoxelizeOptions vo;
        vo.method = m;
        vo.memoryLimitBytes = budget;
        vo.dims = std::array<uint32_t, 3>{r, r, r};
        if (const auto bounds = vox::sceneBounds(scene)) vo.bounds = batchCube(*bounds);
        vo.progress = [&](double) { return interrupt.poll(double(done.load()) / double(srcs.size())); };
        vox::Grid g = vox::voxelizeScene(scene, vo);
        if (doFill) {
          vox::FillOptions fo;
          fo.memoryLimitBytes = budget;
          fo.progress = vo.progress;
          reports[b] = vox::fillSolid(g, scene, fo);
        }
        return g;
      });
      if (cells) {
        bool* p = cells + cube * b;
        std::fill(p, p + cube, false);  // here, not before the loop: the first touch of the pages in parallel too
        vox::forEachVoxelRow(g, [&](const vox::VoxelRow& row) {
          for (uint32_t n = 0; n < row.count; ++n) p[(uint64_t(row.i0 + n) * r + row.j) * r + row.k] = true;
        });
      } else {
        grids[b] = std::move(g);
      }
      interrupt.poll(double(done.fetch_add(1) + 1) / double(srcs.size()));
    });
    if (interrupt.cancelled()) vox::fail<vox::Error>("voxelize_batch cancelled");
  });
  // The warnings voxelize gives, each source's in turn, named by its index.
  for (size_t b = 0; b < srcs.size(); ++b) {
    for (const std::string& w : srcs[b].scene.warnings) warn(srcs[b].describe(w));
    if (doFill)
      if (const std::string w = vox::fillWarning(reports[b]); !w.empty()) warn(srcs[b].describe("fill: " + w));
  }
  if (dense) return out;
  py::list list;
  for (size_t b = 0; b < srcs.size(); ++b)
    list.append(std::make_shared<PyGrid>(vox::GridFile{std::move(srcs[b].scene), std::move(grids[b])}, srcs[b].name));
  return list;
}

// libvox.surface: voxelize with distances (a band wide enough for the level) and extract the level set.
py::tuple surfaceOfSource(const py::object& source, const py::object& resolution, const py::object& dims,
                          const py::object& pitch, const py::object& bounds, const py::object& level,
                          const py::object& halfWidth, const py::object& threads, const py::object& progress) {
  Source src = sourceArg(source, "source", "");
  GridRequest request = gridRequest(resolution, dims, pitch, bounds, py::str("exact"));
  vox::VoxelizeOptions& vo = request.options;
  const double lvl = floatArg(level, "level");
  std::optional<double> half;
  if (!halfWidth.is_none()) {
    half = floatArg(halfWidth, "half_width");
    vox::checkSdfHalfWidth(*half, "half_width");
  }
  const auto nThreads = threadsArg(threads);
  Interrupt interrupt(progressCallable(progress, "surface"));
  vo.progress = [&](double f) { return interrupt.poll(0.2 * f); };
  vox::VoxelMesh mesh = runLong(interrupt, nThreads, [&] {
    const vox::Scene& scene = src.load([&](double) { return interrupt.poll(0); });
    if (request.pitch) applyPitch(*request.pitch, scene, vo);
    return namedAfter(src, [&] {
      const bool userBounds = vo.bounds.has_value();
      vo = vox::withCubicCells(scene, vo);
      if (!userBounds) {
        // Without bounds, room around the scene: two cells, and the level's width for a grown surface, on every
        // side (the same cubic cells), so that the surface is not cut flat at the scene's own bounds.
        const vox::Grid plan = vox::planGrid(scene, vo);
        vox::Box b = plan.bounds;
        std::array<uint32_t, 3> d = plan.dims;
        for (int a = 0; a < 3; ++a) {
          const double h = (b.hi[a] - b.lo[a]) / double(d[a]);
          const double cells = std::ceil(std::max(lvl, 0.0) / h) + 2;
          if (!(cells < double(vox::kMaxCellsPerAxis))) vox::fail<vox::UsageError>("level ", lvl, " is too large");
          b.lo.at(a) -= cells * h;
          b.hi.at(a) += cells * h;
          d[a] = uint32_t(std::min<double>(d[a] + 2 * cells, vox::kMaxCellsPerAxis));
        }
        vo.bounds = b;
        vo.dims = d;
        vo.resolution.reset();
      }
      vox::checkNumericDomainOfPlan(scene, vo, true, false);
      vox::Grid g = vox::voxelizeScene(scene, vo);
      vox::SdfOptions so;
      so.halfWidth = half ? *half : vox::surfaceHalfWidth(g, lvl);
      so.memoryLimitBytes = vo.memoryLimitBytes;
      so.progress = [&](double f) { return interrupt.poll(0.2 + 0.6 * f); };
      vox::storeSignedDistances(g, scene, so, false);
      return vox::extractLevelSurface(g, lvl, nullptr, [&](double f) { return interrupt.poll(0.8 + 0.2 * f); });
    });
  });
  for (const std::string& w : src.scene.warnings) warn(src.describe(w));
  if (!src.scene.planes.empty())
    warn(src.describe(std::to_string(src.scene.planes.size()) + " planes are left out of the signed distances"));
  return surfaceArrays(std::move(mesh));
}

}  // namespace

void bindVoxelize(py::module_& m) {
  m.def("surface", &surfaceOfSource, py::arg("source"), py::kw_only(), py::arg("resolution") = py::none(),
        py::arg("dims") = py::none(), py::arg("pitch") = py::none(), py::arg("bounds") = py::none(),
        py::arg("level") = 0.0, py::arg("half_width") = py::none(), py::arg("threads") = py::none(),
        py::arg("progress") = false, R"doc(
A mesh's watertight twin in one call: voxelize(source, ..., sdf=half_width).surface(level) without keeping the grid.
Returns (vertices (V, 3) float64, faces (F, 3) int64): closed, two-manifold, oriented outward, no zero-area face,
the level set d = level (world units) of the exact signed distance (negative inside by the winding number, so open,
self-intersecting and inconsistently oriented meshes come out closed), linearly interpolated between cell centres.

source, resolution, dims, pitch, bounds, threads and progress as for voxelize (with a resolution, cells exactly
cubic), and without bounds the grid gets two cells (and the level's width) of room on every side, so that the
surface is not cut at the scene's bounds. half_width: the band in cell widths, in (0, 64]; default the smallest that holds the level (at least 3).
Raises InputError when |level| exceeds what the band holds (half_width * h - cell diagonal), UsageError for bad
options, TypeError for wrong types; as voxelize otherwise.
)doc");

  m.def("voxelize", &voxelize, py::arg("source"), py::kw_only(), py::arg("resolution") = py::none(),
        py::arg("dims") = py::none(), py::arg("pitch") = py::none(), py::arg("bounds") = py::none(),
        py::arg("method") = "exact", py::arg("fill") = py::none(), py::arg("sdf") = py::none(),
        py::arg("fraction") = false, py::arg("threads") = py::none(), py::arg("progress") = false, R"doc(
Puts every triangle and sphere of a scene into the closed cells it meets, as `vox-voxelize` does (the same cells and
primitive ids).

source: a path (.obj, .ply, .gltf, .glb, or the course's .txt scenes), a (vertices, faces) pair of arrays
    (vertices (V, 3) float32 or float64, widened exactly; faces (F, 3) integers; triangle i is face i), or any
    object with .vertices and .faces (a trimesh.Trimesh).
resolution: cells on the longest axis, cells as cubic as possible (vox-voxelize --res).
dims: (nx, ny, nz) cells (--grid); one int for all three.
pitch: cell edge length (one number, or three): dims = ceil(extent / pitch), bounds grown symmetrically to whole
    cells. At most one of resolution, dims, pitch; with none, about 3 cells per primitive.
bounds: ((x0, y0, z0), (x1, y1, z1)); default: the bounds of the primitives. Primitives sticking out are kept and
    traced separately.
method: 'exact' (CGAL exact predicates, default), 'sat', 'bbox' or 'center'.
fill: True also marks the empty cells inside closed surfaces as solid (generalized winding number for open meshes).
sdf: a half-width HALF in (0, 64] cell widths: also the signed distance at the centre of every cell within HALF
    smallest cell edges of the surface (vox-voxelize --sdf; Grid.sdf; docs/distance.md).
fraction: True also stores each occupied cell's volume fraction inside the solid (vox-voxelize --fraction;
    Grid.fractions; implies fill, by winding number so that closed cavities stay empty): exact for closed meshes,
    balls to 1e-12 of a cell; open or self-overlapping meshes, ellipsoids and planes raise UsageError.
threads: worker threads (default: all cores).
progress: True for a tqdm bar (when tqdm is installed), or a callable taking the fraction done.

The GIL is released while it works; Ctrl-C raises KeyboardInterrupt within a fraction of a second.
Raises InputError (bad file, with the file and place; bad arrays), UsageError (bad options), LimitError (the grid
would not fit in memory, checked before allocating), TypeError (wrong argument types).
)doc");

  m.def("sdf", &denseSdf, py::arg("source"), py::kw_only(), py::arg("resolution") = py::none(),
        py::arg("dims") = py::none(), py::arg("pitch") = py::none(), py::arg("bounds") = py::none(),
        py::arg("threads") = py::none(), py::arg("progress") = false, R"doc(
The signed distance at the centre of every cell, as a dense (nx, ny, nz) float64 array indexed [i, j, k]: the
Euclidean distance (world units) to the nearest triangle, sphere or ellipsoid (planes are left out, with a
warning), negative inside as fill decides it (closed surfaces exactly, open meshes by the winding number).

The grid is the one voxelize(source, resolution=..., dims=..., pitch=..., bounds=..., sdf=HALF) makes (with a
resolution, cells exactly cubic), so Grid.sdf's band values equal this array's at the band's indices bit for bit,
and that grid's bounds and dims place the cells. source, resolution, dims, pitch, bounds, threads and progress as
for voxelize. The whole array must fit in memory (checked before allocating: LimitError).
)doc");

  m.def("voxelize_batch", &voxelizeBatch, py::arg("sources"), py::arg("resolution") = 64, py::kw_only(),
        py::arg("fill") = py::none(), py::arg("method") = "exact", py::arg("threads") = py::none(),
        py::arg("dense") = true, py::arg("progress") = false, R"doc(
Voxelizes many meshes, spread over worker threads: each source (as for voxelize) in its own cubic grid of
`resolution` cells per axis over its own bounds (cubic cells: the longest axis spans the mesh exactly, the others
are centred on it). Returns np.bool_ of shape (B, R, R, R) indexed [b, i, j, k] (occupied and solid cells), or a
list of Grids when dense=False.

sources: a list (or any iterable) of sources; one path alone is a TypeError (voxelize_batch([path], ...)).
Errors and the importers' warnings of a source start with its index: "sources[1]: faces[0, 2] = 10: ...".
Raises as voxelize does; Ctrl-C raises KeyboardInterrupt within a fraction of a second.
)doc");
}

}  // namespace voxpy
