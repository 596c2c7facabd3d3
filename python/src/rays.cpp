// Grid.intersect and Grid.occluded: batches of rays through the exact grid walk of vox-trace (traceRay, occluded).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "binding.h"
#include "vox/core/error.h"
#include "vox/trace/intersect.h"
#include "vox/trace/traverse.h"

namespace voxpy {

namespace {

// Rays are handed to the workers in runs of this many, and Ctrl-C is looked at between runs.
constexpr size_t kRayGrain = 256;

struct RayBatch {
  std::vector<vox::Vec3> origins, directions;
  std::vector<double> tmax;  // one per ray, or one for all
  size_t size() const { return origins.size(); }
  vox::Ray ray(size_t n) const {
    return vox::Ray{origins[n], directions[n], 0.0, tmax.size() == 1 ? tmax[0] : tmax[n]};
  }
};

RayBatch rayBatch(const py::handle& origins, const py::handle& directions, const py::handle& tmax) {
  RayBatch b;
  b.origins = vec3Array(origins, "origins", true);
  b.directions = vec3Array(directions, "directions", true);
  if (b.origins.size() != b.directions.size())
    vox::fail<vox::InputError>("origins and directions: ", b.origins.size(), " and ", b.directions.size(),
                               " rays; expected the same number");
  if (!isSequence(tmax)) {  // one number for every ray (infinity allowed: no limit)
    b.tmax = {floatArg(tmax, "tmax", true)};
    return b;
  }
  const py::array t = asArray(tmax, "tmax");
  const char kind = t.dtype().kind();
  if (!(kind == 'f' || kind == 'i' || kind == 'u') || t.dtype().itemsize() > 8)
    failType("tmax must be a number or an array of numbers, not an array of ", std::string(py::str(t.dtype())));
  const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(t);
  if (d.ndim() == 1 && d.shape(0) == 1 && b.size() != 1) {
    b.tmax = {d.data()[0]};
  } else if (d.ndim() == 1 && size_t(d.shape(0)) == b.size()) {
    b.tmax.assign(d.data(), d.data() + b.size());
  } else {
    vox::fail<vox::InputError>("tmax: expected a number or ", b.size(), " numbers");
  }
  for (size_t n = 0; n < b.tmax.size(); ++n)
    if (std::isnan(b.tmax[n])) vox::fail<vox::InputError>("tmax[", n, "] is nan");
  return b;
}

// Runs body(first, last) over the rays on worker threads, stopping early on Ctrl-C. simple_partitioner: blocks of at
// most kRayGrain rays, each asking when done; the default partitioner gave a thread a whole share of the rays
// between asks (1.6 s before Ctrl-C acted on 4 million rays).
template <class Body>
void forRays(Interrupt& interrupt, size_t count, Body&& body) {
  std::atomic<size_t> done{0};
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, count, kRayGrain),
      [&](const tbb::blocked_range<size_t>& r) {
        if (interrupt.cancelled()) return;
        body(r.begin(), r.end());
        interrupt.poll(double(done.fetch_add(r.size()) + r.size()) / double(count));
      },
      tbb::simple_partitioner());
  if (interrupt.cancelled()) vox::fail<vox::Error>("tracing cancelled");
}

vox::Vec3 hitNormal(const vox::Accel& accel, const vox::Ray& ray, const vox::Hit& hit) {
  if (hit.prim < accel.triangleCount) return vox::triangleNormal(accel.triangles[hit.prim]);
  const uint32_t s = hit.prim - accel.triangleCount;
  if (s < accel.sphereCount) return vox::sphereNormal(accel.spheres[s], ray, hit.t);
  return vox::planeNormal(accel.planes[s - accel.sphereCount]);
}

// The grid walk (kept by the Grid), or the uniform walk or brute force for accel="uniform" or "none" (built for the
// call into `other`).
const vox::Accel& accelFor(PyGrid& self, vox::AccelKind kind, std::unique_ptr<vox::Accel>& other) {
  if (kind == vox::AccelKind::Grid) return self.accel();
  other = std::make_unique<vox::Accel>(vox::buildAccel(self.scene(), self.grid(), kind));
  return *other;
}

py::tuple intersect(PyGrid& self, const py::handle& origins, const py::handle& directions, const py::handle& tmax,
                    const py::object& threads, const py::object& accelName) {
  const vox::AccelKind kind = enumArg(accelName, "accel", vox::parseAccel);
  const RayBatch rays = rayBatch(origins, directions, tmax);
  const auto nThreads = threadsArg(threads);
  const py::ssize_t n = py::ssize_t(rays.size());
  py::array_t<double> t(n), normal({n, py::ssize_t(3)});
  py::array_t<int64_t> prim(n);
  double* tp = t.mutable_data();
  double* np = normal.mutable_data();
  int64_t* pp = prim.mutable_data();
  Interrupt interrupt;
  runLong(interrupt, nThreads, [&] {
    std::unique_ptr<vox::Accel> none;
    const vox::Accel& accel = accelFor(self, kind, none);
    forRays(interrupt, rays.size(), [&](size_t first, size_t last) {
      for (size_t r = first; r < last; ++r) {
        const vox::Ray ray = rays.ray(r);
        const vox::Hit hit = vox::traceRay(accel, ray);
        const vox::Vec3 nrm = hit.valid() ? hitNormal(accel, ray, hit) : vox::Vec3{0, 0, 0};
        tp[r] = hit.valid() ? hit.t : vox::kInfinity;
        pp[r] = hit.valid() ? int64_t(hit.prim) : -1;
        np[3 * r] = nrm.x, np[3 * r + 1] = nrm.y, np[3 * r + 2] = nrm.z;
      }
    });
  });
  return py::make_tuple(t, prim, normal);
}

py::array_t<bool> occludedRays(PyGrid& self, const py::handle& origins, const py::handle& directions,
                               const py::handle& tmax, const py::object& threads, const py::object& accelName) {
  const vox::AccelKind kind = enumArg(accelName, "accel", vox::parseAccel);
  const RayBatch rays = rayBatch(origins, directions, tmax);
  const auto nThreads = threadsArg(threads);
  py::array_t<bool> out(py::ssize_t(rays.size()));
  bool* p = out.mutable_data();
  Interrupt interrupt;
  runLong(interrupt, nThreads, [&] {
    std::unique_ptr<vox::Accel> none;
    const vox::Accel& accel = accelFor(self, kind, none);
    forRays(interrupt, rays.size(), [&](size_t first, size_t last) {
      for (size_t r = first; r < last; ++r) p[r] = vox::occluded(accel, rays.ray(r));
    });
  });
  return out;
}

}  // namespace

void bindRays(GridClass& grid) {
  grid.def("intersect", &intersect, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = std::numeric_limits<double>::infinity(), py::arg("threads") = py::none(), py::kw_only(),
           py::arg("accel") = "grid",
           R"doc(
The nearest hit of each ray origin + t * direction, t in [0, tmax], through the exact grid walk of vox-trace: the
same hit as testing every primitive (brute force), bit for bit, on exact, sat and bbox grids; ties go to the smaller
primitive id. origins, directions: (R, 3) float (directions need not be unit length: t counts in their lengths);
tmax: a number or (R,) numbers.
Returns t (R,) float64 (inf for a miss), primitive (R,) int64 (ids in the scene's order: an OBJ's triangles in face
order, then spheres, then planes; -1 for a miss) and normal (R, 3) float64 (unit geometric normal, not flipped
towards the ray; zeros for a miss). Planes and primitives outside the grid's bounds are found too.
accel 'uniform' steps through every cell the ray crosses (no jumps over empty boxes), 'none' tests every primitive for
every ray (brute force: the reference the walk equals).
The trace structure is built on the first call and kept. The GIL is released; Ctrl-C stops it.
)doc");
  grid.def("occluded", &occludedRays, py::arg("origins"), py::arg("directions"),
           py::arg("tmax") = std::numeric_limits<double>::infinity(), py::arg("threads") = py::none(), py::kw_only(),
           py::arg("accel") = "grid",
           R"doc(
Whether anything is hit for t in [0, tmax] (shadow rays): (R,) bool, equal to intersect(...)[0] <= tmax.
)doc");
}

}  // namespace voxpy
