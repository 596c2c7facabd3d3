#include "vox/distance/queries.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

#include "vox/core/error.h"
#include "vox/distance/nearest.h"
#include "vox/distance/sdf.h"

namespace vox {

namespace {

// Progress and cancellation of a parallel loop: each finished block reports.
struct QueryProgress {
  const DistanceQueryOptions& options;
  uint64_t total;
  std::atomic<uint64_t> done{0};
  std::atomic<bool> cancelled{false};
  void report(uint64_t count) {
    const uint64_t finished = done += count;
    if (options.progress && !options.progress(double(finished) / double(std::max<uint64_t>(total, 1))))
      cancelled = true;
  }
};

// An upper bound of d(p)^2 from a neighbour q at distance d(q), |p - q| <= step: (d(q) + step)^2, rounded up by a
// relative 1e-12 so that rounding never makes it smaller than the true value.
double neighbourBound2(double d, double step) {
  const double b = (d + step) * (1 + 1e-12);
  return b * b;
}

}  // namespace

void denseSignedDistances(const Grid& grid, const Scene& scene, std::span<double> out,
                          const std::array<uint64_t, 3>& strides, const DistanceQueryOptions& options) {
  const NearestPrimitive nearest(scene);
  const InsideTest insideTest(scene);
  std::array<std::vector<double>, 3> centres;
  for (int a = 0; a < 3; ++a)
    for (uint32_t i = 0; i < grid.dims[a]; ++i) centres[a].push_back(cellCentreOnAxis(grid.bounds, grid.dims, a, i));
  // Rows run along the axis of the smallest stride, so each row's writes are adjacent and each cell's search is
  // bounded by its neighbour's distance.
  const int along = strides[0] <= strides[1] && strides[0] <= strides[2] ? 0 : (strides[1] <= strides[2] ? 1 : 2);
  const int u = along == 0 ? 1 : 0, v = along == 2 ? 1 : 2;
  const uint64_t rows = uint64_t(grid.dims[u]) * grid.dims[v], length = grid.dims[along];
  QueryProgress progress{options, rows};
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rows, 16), [&](const tbb::blocked_range<uint64_t>& r) {
    if (progress.cancelled) return;
    for (uint64_t row = r.begin(); row < r.end(); ++row) {
      uint32_t ijk[3];
      ijk[u] = uint32_t(row % grid.dims[u]);
      ijk[v] = uint32_t(row / grid.dims[u]);
      double previous = INFINITY;
      for (uint32_t s = 0; s < length; ++s) {
        ijk[along] = s;
        const Vec3 c{centres[0][ijk[0]], centres[1][ijk[1]], centres[2][ijk[2]]};
        const double step = s > 0 ? centres[along][s] - centres[along][s - 1] : INFINITY;
        NearestHit hit = nearest.nearest(c, s > 0 ? neighbourBound2(previous, step) : INFINITY);
        if (hit.primitive < 0 && s > 0) hit = nearest.nearest(c);  // the bound was too tight after all
        const double d = std::sqrt(hit.squaredDistance);
        previous = d;
        const uint64_t key = cellKey(grid.dims, ijk[0], ijk[1], ijk[2]);
        const bool inside = findCell(grid, key) >= 0 ? d > 0 && insideTest.inside(c) : isSolid(grid, key);
        out[ijk[0] * strides[0] + ijk[1] * strides[1] + ijk[2] * strides[2]] = inside ? -d : d;
      }
    }
    progress.report(r.size());
  });
  if (progress.cancelled) fail<Error>("signed distances cancelled");
}

void pointDistances(const Scene& scene, std::span<const double> points, bool signedDistance,
                    const PointDistanceOutput& out, const DistanceQueryOptions& options) {
  const size_t n = points.size() / 3;
  for (size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i]))
      fail<InputError>("points[", i / 3, ", ", i % 3, "] is ", points[i], ": coordinates must be finite");
  const NearestPrimitive nearest(scene);
  std::optional<InsideTest> insideTest;
  if (signedDistance) insideTest.emplace(scene);
  QueryProgress progress{options, n};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    if (progress.cancelled) return;
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const Vec3 p{points[3 * i], points[3 * i + 1], points[3 * i + 2]};
      const NearestHit hit = nearest.nearest(p);
      const double d = std::sqrt(hit.squaredDistance);
      const Vec3 c = nearest.closestPoint(hit.primitive, p);
      out.distance[i] = insideTest && d > 0 && insideTest->inside(p) ? -d : d;
      out.primitive[i] = hit.primitive;
      for (int a = 0; a < 3; ++a) out.closest[3 * i + a] = c[a];
    }
    progress.report(r.size());
  });
  if (progress.cancelled) fail<Error>("point distances cancelled");
}

}  // namespace vox
