#include "vox/distance/sdf.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "vox/core/error.h"
#include "vox/voxelize/fill.h"

namespace vox {

InsideTest::InsideTest(const Scene& scene)
    : tree_(buildWindingTree({scene.triangles.data(), scene.triangles.size()})) {
  shapes_.reserve(scene.spheres.size());
  for (const Sphere& s : scene.spheres) shapes_.push_back(ellipsoidShape(s));
}

bool InsideTest::inside(const Vec3& p) const {
  for (const EllipsoidShape& s : shapes_)
    if (insideEllipsoid(s, p)) return true;
  return !tree_.nodes.empty() && std::fabs(windingNumber(tree_, p)) >= kWindingThreshold;
}

void checkSdfHalfWidth(double halfWidth, const char* what) {
  if (!(halfWidth > 0) || !(halfWidth <= kMaxSdfHalfWidth))
    fail<UsageError>(what, ": half-width ", halfWidth, " must be a number in (0, ", kMaxSdfHalfWidth,
                     "] cell widths");
}

Vec3 cellCentre(const Grid& grid, uint32_t i, uint32_t j, uint32_t k) {
  const uint32_t ijk[3] = {i, j, k};
  Vec3 c;
  for (int a = 0; a < 3; ++a)
    c.at(a) = 0.5 * (cellBoundary(grid.bounds, grid.dims, a, ijk[a]) + cellBoundary(grid.bounds, grid.dims, a, ijk[a] + 1));
  return c;
}

namespace {

struct Candidate {
  uint64_t key;
  double d2;  // squared distance from the cell's centre to one primitive
  bool operator<(const Candidate& o) const { return key != o.key ? key < o.key : d2 < o.d2; }
};

// The cells' centres along each axis, computed once: cellCentre for every index.
struct Centres {
  std::array<std::vector<double>, 3> axis;
  explicit Centres(const Grid& grid) {
    for (int a = 0; a < 3; ++a) {
      axis[a].resize(grid.dims[a]);
      for (uint32_t i = 0; i < grid.dims[a]; ++i)
        axis[a][i] = 0.5 * (cellBoundary(grid.bounds, grid.dims, a, i) + cellBoundary(grid.bounds, grid.dims, a, i + 1));
    }
  }
};

double smallestCellEdge(const Grid& grid) {
  double h = INFINITY;
  for (int a = 0; a < 3; ++a) h = std::min(h, (grid.bounds.hi[a] - grid.bounds.lo[a]) / grid.dims[a]);
  return h;
}

// Emits the cells of box [lo - reach, hi + reach] whose centre lies within `reach` of a primitive, as told by
// `squaredDistance(centre)` (negative: rejected early).
template <typename SquaredDistance>
void emitCells(const Grid& grid, const Centres& centres, const Vec3& lo, const Vec3& hi, double reach,
               const SquaredDistance& squaredDistance, std::vector<Candidate>& out) {
  std::array<std::array<int64_t, 2>, 3> range;
  for (int a = 0; a < 3; ++a) {
    range[a] = cellRange(grid.bounds, grid.dims, a, lo[a] - reach, hi[a] + reach);
    if (range[a][0] > range[a][1]) return;
  }
  const double reach2 = reach * reach;
  for (int64_t k = range[2][0]; k <= range[2][1]; ++k)
    for (int64_t j = range[1][0]; j <= range[1][1]; ++j)
      for (int64_t i = range[0][0]; i <= range[0][1]; ++i) {
        const Vec3 c{centres.axis[0][i], centres.axis[1][j], centres.axis[2][k]};
        const double d2 = squaredDistance(c);
        if (d2 >= 0 && d2 <= reach2) out.push_back({cellKey(grid.dims, i, j, k), d2});
      }
}

// Every (cell, squared distance) pair of the band, one per primitive near the cell, in no particular order.
std::vector<Candidate> bandCandidates(const Grid& grid, const Scene& scene, double reach, const SdfOptions& options) {
  const Centres centres(grid);
  std::vector<EllipsoidShape> shapes;
  for (const Sphere& s : scene.spheres) shapes.push_back(ellipsoidShape(s));
  const size_t triangles = scene.triangles.size(), prims = triangles + shapes.size();
  tbb::enumerable_thread_specific<std::vector<Candidate>> locals;
  std::atomic<uint64_t> done{0}, emitted{0};
  std::atomic<bool> cancelled{false}, overBudget{false};
  const uint64_t maxCandidates = options.memoryLimitBytes / (2 * sizeof(Candidate));  // the pairs, then the merge
  tbb::parallel_for(tbb::blocked_range<size_t>(0, prims, 64), [&](const tbb::blocked_range<size_t>& r) {
    if (cancelled || overBudget) return;
    std::vector<Candidate>& out = locals.local();
    const size_t before = out.size();
    for (size_t p = r.begin(); p < r.end(); ++p) {
      if (p < triangles) {
        const Triangle& t = scene.triangles[p];
        const Vec3 n = cross(t.v[1] - t.v[0], t.v[2] - t.v[0]);
        const double planeReach = reach * length(n);  // |n . (c - a)| > reach |n|: the plane alone is too far
        emitCells(grid, centres, minVec(minVec(t.v[0], t.v[1]), t.v[2]), maxVec(maxVec(t.v[0], t.v[1]), t.v[2]),
                  reach, [&](const Vec3& c) {
                    if (std::fabs(dot(n, c - t.v[0])) > planeReach) return -1.0;
                    return squaredDistanceToTriangle(t.v[0], t.v[1], t.v[2], c);
                  }, out);
      } else {
        const EllipsoidShape& s = shapes[p - triangles];
        const double big = s.semi.x;  // semi-axes descending
        emitCells(grid, centres, s.center - Vec3{big, big, big}, s.center + Vec3{big, big, big}, reach,
                  [&](const Vec3& c) {
                    const Vec3 d = c - closestPointOnEllipsoid(s, c);
                    return dot(d, d);
                  }, out);
      }
    }
    if ((emitted += out.size() - before) > maxCandidates) overBudget = true;
    const uint64_t finished = done += r.size();
    if (options.progress && !options.progress(0.8 * double(finished) / double(prims))) cancelled = true;
  });
  if (cancelled) fail<Error>("signed distances cancelled");
  if (overBudget)
    fail<LimitError>("signed distance band: more than ", maxCandidates, " cell-primitive distances within ",
                     options.halfWidth, " cell widths, over the memory limit of ", options.memoryLimitBytes >> 20,
                     " MiB; use a narrower band or fewer cells");
  std::vector<Candidate> all;
  all.reserve(emitted);
  for (auto& local : locals) all.insert(all.end(), local.begin(), local.end());
  return all;
}

}  // namespace

SdfBand signedDistanceBand(const Grid& grid, const Scene& scene, const SdfOptions& options, SdfReport* report) {
  checkSdfHalfWidth(options.halfWidth, "--sdf");
  const double reach = options.halfWidth * smallestCellEdge(grid);
  std::vector<Candidate> all = bandCandidates(grid, scene, reach, options);
  tbb::parallel_sort(all.begin(), all.end());  // by key, then distance: each key's first entry is its nearest
  SdfBand band;
  for (size_t i = 0; i < all.size(); ++i)
    if (i == 0 || all[i].key != all[i - 1].key) {
      band.keys.push_back(all[i].key);
      band.values.push_back(all[i].d2);
    }
  const uint64_t candidates = all.size();
  std::vector<Candidate>().swap(all);
  // Signs: an empty cell lies wholly on one side, which the fill decided; an occupied cell's centre is tested.
  const InsideTest insideTest(scene);
  std::atomic<uint64_t> queries{0}, done{0};
  std::atomic<bool> cancelled{false};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, band.keys.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    if (cancelled) return;
    uint64_t local = 0;
    for (size_t b = r.begin(); b < r.end(); ++b) {
      const uint64_t key = band.keys[b];
      const double d = std::sqrt(band.values[b]);
      bool inside;
      if (findCell(grid, key) >= 0) {
        const auto ijk = cellIndex(grid.dims, key);
        inside = d > 0 && insideTest.inside(cellCentre(grid, ijk[0], ijk[1], ijk[2]));
        ++local;
      } else {
        inside = isSolid(grid, key);
      }
      band.values[b] = inside ? -d : d;
    }
    queries += local;
    const uint64_t finished = done += r.size();
    if (options.progress && !options.progress(0.8 + 0.2 * double(finished) / double(band.keys.size())))
      cancelled = true;
  });
  if (cancelled) fail<Error>("signed distances cancelled");
  if (report) {
    report->candidates = candidates;
    report->insideQueries = queries;
    report->planesLeftOut = scene.planes.size();
  }
  return band;
}

}  // namespace vox
