#include "vox/distance/queries.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "vox/core/error.h"
#include "vox/distance/centre_signs.h"
#include "vox/distance/nearest.h"
#include "vox/distance/sdf.h"

namespace vox {

namespace {

// Progress and cancellation of a parallel loop: each finished block reports.
struct QueryProgress {
  const DistanceQueryOptions& options;
  uint64_t total;
  double from = 0;  // the part of options.progress this loop reports: [from, 1]
  std::atomic<uint64_t> done{0};
  std::atomic<bool> cancelled{false};
  void report(uint64_t count) {
    const uint64_t finished = done += count;
    const double f = double(finished) / double(std::max<uint64_t>(total, 1));
    if (options.progress && !options.progress(from + (1 - from) * f)) cancelled = true;
  }
};

}  // namespace

namespace {

// The dense field's bricks of cells and the most subtrees their frontier keeps: measured with bench/bench_distance
// (docs/distance.md, "The dense field by bricks").
constexpr uint32_t kDenseBrick = 4;
constexpr size_t kDenseFrontier = 16;

void framedDenseSignedDistances(const Grid& grid, const Scene& scene, std::span<double> out,
                                const std::array<uint64_t, 3>& strides, const DistanceQueryOptions& options);

}  // namespace

// Computed in the scene's power-of-two frame (docs/limits.md "Numeric domain"), as the band is, so the two agree bit
// for bit at every scale.
void denseSignedDistances(const Grid& grid, const Scene& scene, std::span<double> out,
                          const std::array<uint64_t, 3>& strides, const DistanceQueryOptions& options) {
  const PowerOfTwoFrame frame = sceneFrame(scene);
  checkNumericDomain(scene, grid.bounds, grid.dims, frame, true, "sdf");
  if (frame.identity()) return framedDenseSignedDistances(grid, scene, out, strides, options);
  Grid framed = grid;  // the cells and runs as they are, the bounds in the frame
  framed.bounds = frame.toFrame(grid.bounds);
  framedDenseSignedDistances(framed, sceneInFrame(scene, frame), out, strides, options);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.size(), 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) out[i] = frame.toWorld(out[i]);
  });
}

namespace {

void framedDenseSignedDistances(const Grid& grid, const Scene& scene, std::span<double> out,
                                const std::array<uint64_t, 3>& strides, const DistanceQueryOptions& options) {
  const NearestPrimitive nearest(scene);
  std::function<bool(double)> signProgress;
  if (options.progress) signProgress = [&](double f) { return options.progress(0.1 * f); };
  // Signs first, a row along x at a time (its crossings found once), in key order: one byte per cell beside the
  // field's eight.
  std::vector<uint8_t> inside;
  {
    const InsideTest test(scene);
    const uint64_t rowCount = uint64_t(grid.dims[1]) * grid.dims[2];
    inside.assign(grid.cellCount(), 0);
    std::atomic<uint64_t> done{0};
    std::atomic<bool> cancelled{false};
    const std::array<std::vector<double>, 3> c = cellCentresByAxis(grid);
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rowCount, 16), [&](const tbb::blocked_range<uint64_t>& r) {
      if (cancelled) return;
      std::vector<InsideTest::Crossing> crossings;
      for (uint64_t row = r.begin(); row < r.end(); ++row) {
        const double qy = c[1][row % grid.dims[1]], qz = c[2][row / grid.dims[1]];
        test.rowCrossings(qy, qz, crossings);
        for (uint32_t i = 0; i < grid.dims[0]; ++i)
          inside[row * grid.dims[0] + i] = test.inside({c[0][i], qy, qz}, crossings);
      }
      const uint64_t finished = done += r.size();
      if (signProgress && !signProgress(double(finished) / double(std::max<uint64_t>(rowCount, 1)))) cancelled = true;
    });
    if (cancelled) fail<Error>("signed distances cancelled");
  }
  const std::array<std::vector<double>, 3> centres = cellCentresByAxis(grid);
  // Bricks of cells, each brick's rows along the axis of the smallest stride, so each row's writes are adjacent and
  // each cell's search starts from its neighbour's nearest primitive, and from the brick's frontier: the subtrees
  // that can hold a nearest primitive of any of its cells, found once for the brick (NearestPrimitive::gather).
  const int along = strides[0] <= strides[1] && strides[0] <= strides[2] ? 0 : (strides[1] <= strides[2] ? 1 : 2);
  const int u = along == 0 ? 1 : 0, v = along == 2 ? 1 : 2;
  std::array<uint32_t, 3> bricks;
  for (int a = 0; a < 3; ++a) bricks[size_t(a)] = (grid.dims[a] + kDenseBrick - 1) / kDenseBrick;
  const uint64_t brickCount = uint64_t(bricks[0]) * bricks[1] * bricks[2];
  QueryProgress progress{options, brickCount, 0.1};
  tbb::enumerable_thread_specific<NearestPrimitive::Frontier> frontiers;
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, brickCount, 4), [&](const tbb::blocked_range<uint64_t>& r) {
    if (progress.cancelled) return;
    NearestPrimitive::Frontier& frontier = frontiers.local();
    int64_t previous = -1;  // the nearest primitive of the brick before
    for (uint64_t b = r.begin(); b < r.end(); ++b) {
      std::array<uint32_t, 3> lo, hi;  // the brick's cells, [lo, hi)
      const uint64_t index[3] = {b % bricks[0], b / bricks[0] % bricks[1], b / (uint64_t(bricks[0]) * bricks[1])};
      for (int a = 0; a < 3; ++a) {
        lo[size_t(a)] = uint32_t(index[a]) * kDenseBrick;
        hi[size_t(a)] = std::min(lo[size_t(a)] + kDenseBrick, grid.dims[a]);
      }
      // The brick's middle cell: its nearest primitive's distance plus the farthest cell's bounds every cell's.
      Vec3 middle;
      for (int a = 0; a < 3; ++a) middle.at(a) = centres[size_t(a)][(lo[size_t(a)] + hi[size_t(a)] - 1) / 2];
      const NearestHit first = nearest.nearestFrom(middle, previous);
      double radius2 = 0;
      for (int corner = 0; corner < 8; ++corner) {
        Vec3 c;
        for (int a = 0; a < 3; ++a) c.at(a) = centres[size_t(a)][corner >> a & 1 ? hi[size_t(a)] - 1 : lo[size_t(a)]];
        radius2 = std::max(radius2, dot(c - middle, c - middle));
      }
      const double radius = std::sqrt(radius2) * (1 + 0x1p-40);  // above the real distance of every cell
      nearest.gather(middle, radius, (std::sqrt(first.squaredDistance) + radius) * (1 + 0x1p-40), kDenseFrontier,
                     frontier);
      previous = first.primitive;
      uint32_t ijk[3];
      for (ijk[v] = lo[size_t(v)]; ijk[v] < hi[size_t(v)]; ++ijk[v])
        for (ijk[u] = lo[size_t(u)]; ijk[u] < hi[size_t(u)]; ++ijk[u]) {
          int64_t seed = first.primitive;
          for (ijk[along] = lo[size_t(along)]; ijk[along] < hi[size_t(along)]; ++ijk[along]) {
            const Vec3 c{centres[0][ijk[0]], centres[1][ijk[1]], centres[2][ijk[2]]};
            const NearestHit hit = nearest.nearestFrom(c, seed, frontier);
            seed = hit.primitive;
            const double d = std::sqrt(hit.squaredDistance);
            const bool in = d > 0 && inside[cellKey(grid.dims, ijk[0], ijk[1], ijk[2])];  // on the surface: +0
            out[ijk[0] * strides[0] + ijk[1] * strides[1] + ijk[2] * strides[2]] = in ? -d : d;
          }
        }
    }
    progress.report(r.size());
  });
  if (progress.cancelled) fail<Error>("signed distances cancelled");
}

// The points' indices in Morton order of their positions quantized to 2^21 steps per axis over their bounding box:
// consecutive points are then near each other, so each one's search can start from the one before's answer.
std::vector<uint32_t> spatialOrder(std::span<const double> points) {
  const size_t n = points.size() / 3;
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi = lo * -1.0;
  for (size_t i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      lo.at(a) = std::min(lo[a], points[3 * i + a]);
      hi.at(a) = std::max(hi[a], points[3 * i + a]);
    }
  const auto spread = [](uint64_t v) {  // the 21 bits of v at every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    return (v | v << 2) & 0x1249249249249249ull;
  };
  std::vector<std::pair<uint64_t, uint32_t>> keyed(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const double extent = hi[a] - lo[a];
      const double t = extent > 0 ? (points[3 * i + a] - lo[a]) / extent : 0;
      key |= spread(uint64_t(std::clamp(t, 0.0, 1.0) * double(0x1fffff))) << a;
    }
    keyed[i] = {key, uint32_t(i)};
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> order(n);
  for (size_t k = 0; k < n; ++k) order[k] = keyed[k].second;
  return order;
}

void checkPoints(std::span<const double> points, const PowerOfTwoFrame& frame) {
  for (size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i]))
      fail<InputError>("points[", i / 3, ", ", i % 3, "] is ", points[i], ": coordinates must be finite");
  checkPointsInDomain(points, frame);
  if (points.size() / 3 > UINT32_MAX)
    fail<LimitError>("point distances: ", points.size() / 3, " points, more than 2^32 - 1 in one call");
}

// pointDistances after checkPoints. Each point is scaled into the search's frame and its answer back out of it.
void checkedPointDistances(const NearestPrimitive& nearest, const InsideTest* insideTest,
                           std::span<const double> points, const PointDistanceOutput& out,
                           const DistanceQueryOptions& options) {
  VOX_CHECK(!insideTest || insideTest->frame() == nearest.frame());
  const PowerOfTwoFrame& frame = nearest.frame();
  const size_t n = points.size() / 3;
  const std::vector<uint32_t> order = spatialOrder(points);
  QueryProgress progress{options, n};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    if (progress.cancelled) return;
    // The nearest primitive of the point before in spatial order: this one's search starts there.
    int64_t previous = -1;
    for (size_t k = r.begin(); k < r.end(); ++k) {
      const size_t i = order[k];
      const Vec3 p = frame.toFrame(Vec3{points[3 * i], points[3 * i + 1], points[3 * i + 2]});
      const NearestHit hit = nearest.nearestFrom(p, previous);
      previous = hit.primitive;
      const double d = frame.toWorld(std::sqrt(hit.squaredDistance));
      const Vec3 c = frame.toWorld(nearest.closestPoint(hit.primitive, p));
      out.distance[i] = insideTest && d > 0 && insideTest->inside(p) ? -d : d;
      out.primitive[i] = hit.primitive;
      for (int a = 0; a < 3; ++a) out.closest[3 * i + a] = c[a];
    }
    progress.report(r.size());
  });
  if (progress.cancelled) fail<Error>("point distances cancelled");
}

}  // namespace

void pointDistances(const Scene& scene, std::span<const double> points, bool signedDistance,
                    const PointDistanceOutput& out, const DistanceQueryOptions& options) {
  const PowerOfTwoFrame frame = sceneFrame(scene);
  checkPoints(points, frame);  // before the structures are built
  const NearestPrimitive nearest(scene, frame);
  std::optional<InsideTest> insideTest;
  if (signedDistance) insideTest.emplace(scene, frame);
  checkedPointDistances(nearest, insideTest ? &*insideTest : nullptr, points, out, options);
}

void pointDistances(const NearestPrimitive& nearest, const InsideTest* insideTest, std::span<const double> points,
                    const PointDistanceOutput& out, const DistanceQueryOptions& options) {
  checkPoints(points, nearest.frame());
  checkedPointDistances(nearest, insideTest, points, out, options);
}

}  // namespace vox
