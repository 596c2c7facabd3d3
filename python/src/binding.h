// What the files of the Python binding share (STYLE.md convention 13): the Grid object, the conversion of numpy
// arguments at the border, and the plumbing of long calls (GIL released, worker threads, Ctrl-C, progress). The
// binding converts and delegates; every algorithm is the library's.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "convert.h"
#include "vox/core/error.h"
#include "vox/core/grid.h"
#include "vox/core/scene.h"
#include "vox/io/grid_file.h"
#include "vox/distance/nearest.h"
#include "vox/distance/sdf.h"
#include "vox/export/voxel_mesh.h"
#include "vox/trace/accel.h"

namespace voxpy {

namespace py = pybind11;

// ---- The Grid object (grid.cpp) ----

// A grid with the scene it was voxelized from (read-only once made). The trace-time structure is built on first use
// (intersect, occluded, render) and kept.
// A structure built on first use from any thread and kept (std::call_once): what a grid's ray and distance calls
// query again and again. A build that throws leaves it unbuilt, to be tried again.
template <typename T>
class BuiltOnce {
 public:
  template <typename Make>
  const T& get(const Make& make) {
    std::call_once(once_, [&] { value_ = std::make_unique<T>(make()); });
    return *value_;
  }

 private:
  std::once_flag once_;
  std::unique_ptr<T> value_;
};

class PyGrid {
 public:
  // `source`: the file system bytes of the path it came from, or "<arrays>".
  PyGrid(vox::GridFile file, std::string source);
  const vox::GridFile& file() const { return *file_; }
  const vox::Grid& grid() const { return file_->grid; }
  const vox::Scene& scene() const { return file_->scene; }
  // Where it came from: a path's bytes, or "<arrays>"; named in messages (decoded with replacement).
  const std::string& source() const { return source_; }
  // The Accel of the grid walk, built once (thread-safe); call with the GIL released, it can take a while.
  const vox::Accel& accel();
  // Grid.distance's search structure and inside test, each built on first use (thread-safe) and kept, as a
  // RaycastingScene keeps Open3D's: later calls only query.
  const vox::NearestPrimitive& nearest();
  const vox::InsideTest& insideTest();

 private:
  std::shared_ptr<const vox::GridFile> file_;
  std::string source_;
  BuiltOnce<vox::Accel> accel_;
  BuiltOnce<vox::NearestPrimitive> nearest_;
  BuiltOnce<vox::InsideTest> insideTest_;
};

// TypeError unless `obj`, when it is a libvox.Grid, has its C++ object: one made by pybind11's base __new__ (which
// bypasses Grid.__new__'s refusal) has none, and pybind11 would hand the binding uninitialised memory as a PyGrid.
void checkInitialised(const py::handle& obj);

}  // namespace voxpy

// Every Grid argument and `self` of the binding is loaded through here (type_caster<PyGrid>), so no call can reach
// a Grid without its C++ object (issue 45: .dims, pickle.dumps and repr read garbage).
namespace pybind11::detail {
template <>
class type_caster<voxpy::PyGrid> : public type_caster_base<voxpy::PyGrid> {
 public:
  bool load(handle src, bool convert) {
    voxpy::checkInitialised(src);
    return type_caster_base<voxpy::PyGrid>::load(src, convert);
  }
};
}  // namespace pybind11::detail

namespace voxpy {

// ---- Long calls (call.cpp) ----

// Lets a long library call, run with the GIL released, notice Ctrl-C and report progress. The library calls
// poll(fraction) from its worker threads (VoxelizeOptions::progress and friends); on the Python thread that made
// the call, at most every kPollSeconds, poll takes the GIL briefly to run Python's signal handlers
// (PyErr_CheckSignals: only that thread can run them) and the progress callable. When either raises (a
// KeyboardInterrupt, or an error of the callable), poll returns false from then on so the library cancels, and
// finish() raises that Python error instead of the library's "cancelled" error.
class Interrupt {
 public:
  static constexpr double kPollSeconds = 0.02;

  // `progress`: None, or a callable taking the fraction done in [0, 1]. Construct with the GIL held.
  explicit Interrupt(py::object progress = py::none());
  ~Interrupt();
  Interrupt(const Interrupt&) = delete;
  Interrupt& operator=(const Interrupt&) = delete;

  // From any thread, without the GIL. False once the call should stop.
  bool poll(double fraction);
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  // With the GIL held, after the library call returned (`completed`) or threw: raises the pending Python error, if
  // any; else, when completed, reports the fraction 1 to the progress callable.
  void finish(bool completed = true);

 private:
  std::thread::id caller_;
  std::atomic<bool> cancelled_{false};
  std::atomic<double> fraction_{0};
  std::chrono::steady_clock::time_point lastPoll_;
  std::unique_ptr<py::error_already_set> error_;
  py::object progress_;
  double reported_ = -1;
};

// Makes the callable of a `progress` argument: None or False for none, True for a tqdm bar labelled `label` (none
// when tqdm is not installed), or a callable taking the fraction done. TypeError for anything else.
py::object progressCallable(const py::object& progress, const char* label);

// Runs `work` with the GIL released, on `threads` worker threads (a TBB arena of that many; the caller's when
// nullopt), then raises what `interrupt` caught (KeyboardInterrupt) in place of the library's error or result.
template <class Work>
auto runLong(Interrupt& interrupt, std::optional<int> threads, Work&& work) -> decltype(work());
// Helper of runLong: runs `body` in an arena of `threads` threads, or directly.
void inArena(std::optional<int> threads, const std::function<void()>& body);
// vox::memoryBudgetBytes(), read once per process as the tools read it (VOX_MEMORY_LIMIT_MB at the first call).
uint64_t memoryBudget();

template <class Work>
auto runLong(Interrupt& interrupt, std::optional<int> threads, Work&& work) -> decltype(work()) {
  using Result = decltype(work());
  try {
    if constexpr (std::is_void_v<Result>) {
      {
        py::gil_scoped_release release;
        inArena(threads, [&] { work(); });
      }
      interrupt.finish();
    } else {
      std::optional<Result> result;
      {
        py::gil_scoped_release release;
        inArena(threads, [&] { result.emplace(work()); });
      }
      interrupt.finish();
      return std::move(*result);
    }
  } catch (const py::error_already_set&) {
    throw;
  } catch (...) {
    interrupt.finish(false);  // a KeyboardInterrupt replaces the library's "cancelled"
    throw;
  }
}

// ---- Arguments (arrays.cpp) ----

// np.asarray(obj): TypeError naming `name` for a str, bytes or what numpy cannot take; InputError for a ragged
// sequence (rows of different lengths), whose shape is the problem, as for an array of the wrong shape.
py::array asArray(const py::handle& obj, const char* name);
// An (N, 3) array of coordinates as doubles: float16/32/64 widened exactly, integers up to 2^53 exactly. TypeError
// for another dtype; InputError naming `name` for another shape, an empty array (unless allowEmpty) or a value that
// is not finite.
std::vector<vox::Vec3> vec3Array(const py::handle& obj, const char* name, bool allowEmpty = false);
// An (F, 3) integer array of indices into `vertexCount` vertices. TypeError for a non-integer dtype; InputError for
// another shape, an empty array or an index out of range.
std::vector<std::array<uint32_t, 3>> faceArray(const py::handle& obj, const char* name, size_t vertexCount);
// A triangle scene from vertex and face arrays (triangle i is face i), with the importers' default white material.
vox::Scene sceneFromArrays(const py::handle& vertices, const py::handle& faces);
// A numpy array of element type T over the memory of `data` (no copy), which it takes over and frees when the array
// is freed: T may differ from U where the layout allows (a Vec3 is three doubles; uint32 ids below 2^31 read as
// int32). Read-only when `readOnly`.
template <class T, class U>
py::array_t<T> adoptVector(std::vector<U>&& data, std::vector<py::ssize_t> shape, bool readOnly = false) {
  static_assert(sizeof(U) % sizeof(T) == 0 && std::is_standard_layout_v<U>);
  auto* owned = new std::vector<U>(std::move(data));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<U>*>(p); });
  py::array_t<T> out(shape, reinterpret_cast<const T*>(owned->data()), free);
  if (readOnly) py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

// A read-only numpy view of the memory at `data`, of `shape`, owned by `base` (which the array keeps alive).
template <class T>
py::array_t<T> readOnlyView(const T* data, std::vector<py::ssize_t> shape, py::handle base) {
  py::array_t<T> out(shape, data, base);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

// ---- Registration, one function per file ----
using GridClass = py::class_<PyGrid, std::shared_ptr<PyGrid>>;
void bindErrors(py::module_& m);
GridClass bindGrid(py::module_& m);
void bindVoxelize(py::module_& m);
void bindSave(GridClass& grid);
void bindRays(GridClass& grid);
void bindRender(py::module_& m);
void bindMesh(GridClass& grid);
// (vertices (V, 3) float64, faces (F, 3) int64) of a level surface (Grid.surface, libvox.surface).
py::tuple surfaceArrays(vox::VoxelMesh&& mesh);
void bindBench(py::module_& m);
void bindDistance(GridClass& grid);

}  // namespace voxpy
