// Grid.distance: the nearest primitive of any points, the call shape of Open3D's compute_signed_distance, pysdf and
// libigl's signed_distance (DESIGN.md "Distance and volume").
#include "binding.h"
#include "vox/core/memory_budget.h"
#include "vox/distance/queries.h"

namespace voxpy {

namespace {

py::tuple distance(PyGrid& self, const py::handle& points, const py::object& signedArg, const py::object& threads) {
  const std::vector<vox::Vec3> q = vec3Array(points, "points", true);
  const bool isSigned = boolArg(signedArg, "signed");
  const auto nThreads = threadsArg(threads);
  const auto n = py::ssize_t(q.size());
  vox::checkMemory(double(n) * 48, self.source(), "distance()");
  py::array_t<double> d(n), closest({n, py::ssize_t(3)});
  py::array_t<int64_t> primitive(n);
  const vox::PointDistanceOutput out{
      {d.mutable_data(), q.size()}, {primitive.mutable_data(), q.size()}, {closest.mutable_data(), 3 * q.size()}};
  Interrupt interrupt;
  vox::DistanceQueryOptions o;
  o.progress = [&](double f) { return interrupt.poll(f); };
  const std::span<const double> flat(&q.data()->x, 3 * q.size());  // Vec3 is three adjacent doubles
  runLong(interrupt, nThreads,
          [&] { vox::pointDistances(self.nearest(), isSigned ? &self.insideTest() : nullptr, flat, out, o); });
  if (!self.scene().planes.empty())
    warn(self.source() + ": " + std::to_string(self.scene().planes.size()) + " planes are left out of the distances");
  return py::make_tuple(d, primitive, closest);
}

}  // namespace

void bindDistance(GridClass& grid) {
  grid.def("distance", &distance, py::arg("points"), py::arg("signed") = true, py::arg("threads") = py::none(),
           R"doc(
The nearest triangle, sphere or ellipsoid (planes are left out) of each point: (distance (P,) float64, primitive
(P,) int64, closest (P, 3) float64). The distance is Euclidean in world units, negative inside when signed (inside
as fill decides it: closed surfaces exactly, open meshes by the generalized winding number); primitive is the id
of Grid.cell_primitives (triangles, then spheres), the lowest on ties; closest is that primitive's nearest point.
A scene without bounded primitives gives inf, -1 and NaN. The same distances as Grid.sdf and libvox.sdf, bit for
bit, at the same points.

points: (P, 3) array of finite coordinates (float32 widened exactly). threads: worker threads (default: all).
The GIL is released while it works; Ctrl-C raises KeyboardInterrupt. Raises InputError for a bad array or a
coordinate that is not finite, TypeError for a wrong type, LimitError when the outputs do not fit in memory.
)doc");
}

}  // namespace voxpy
