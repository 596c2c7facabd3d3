// Volume fractions. The method, for a closed, consistently oriented mesh whose winding number w is 0 or 1: with
// F = (x - x0, 0, 0), div F = 1, and the divergence theorem over the cell C = [x0, x1] x [y0, y1] x [z0, z1] gives
//   vol(C and solid) = integral over C of w = sum over triangles of the flux of F through (triangle and C)
//                      + (x1 - x0) * integral of w over the face x = x1,
// since w jumps by -1 across each triangle along its outward normal and F vanishes on x = x0. The face integral is
// the same one dimension down with G = (y - y0, 0) (the triangles' sections by x = x1 are its curves), ending in
// (y1 - y0) * the integral of w along the edge (x1, y1, z in [z0, z1]); that integral comes from the crossings of the
// whole vertical line x = x1, y = y1 with the mesh, sorted, starting below the grid where w = 0, so no point is ever
// classified on its own. Every decision of which side of a cell plane or line a point of the mesh lies on is exact
// (integer comparisons of coordinates, orient2d with CGAL behind a filter) and made in one perturbed world
// (mesh_cell_volume.h), so a face in a cell plane, an edge on a cell line or a vertex on a corner is counted once.
//
// Error: what is left is rounding in quantities that the volume depends on continuously: vertices translated to the
// cell's corner, the clip points and section points (relative error a few eps of the distance of the triangle's
// vertices from the cell), and the sums. For a cell holding m triangles of extent at most E, the error is of order
// m * eps * (E / h) of the cell volume (h the smallest cell edge): below 1e-12 for m * E / h up to about 1e3.
// The sums over lines are shared by the cells along them, which keeps neighbouring cells consistent.
#include "vox/volume/fractions.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/power_of_two_frame.h"
#include "vox/voxelize/open_edges.h"
#include "volume/ball_box.h"
#include "volume/mesh_cell_volume.h"

namespace vox {

namespace {

using volume::CellPlanes;
using volume::LineCrossing;

struct Ball {
  Vec3 center;
  double radius = 0;
};

// The ball a sphere is: its transform must be a rotation times a uniform scale plus a translation, to rounding.
Ball ballOf(const Sphere& s, size_t index) {
  if (!s.isEllipsoid()) return {s.center, s.radius};
  const auto& m = s.transform.m;
  double g[3][3] = {}, trace = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) g[i][j] += m[k][i] * m[k][j];
      if (i == j) trace += g[i][j];
    }
  const double s2 = trace / 3;
  double deviation = std::fabs(m[3][0]) + std::fabs(m[3][1]) + std::fabs(m[3][2]) + std::fabs(m[3][3] - 1) * s2;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) deviation = std::max(deviation, std::fabs(g[i][j] - (i == j ? s2 : 0)));
  if (!(deviation <= 16 * std::numeric_limits<double>::epsilon() * s2))
    fail<UsageError>("volume fractions: sphere ", index,
                     " is an ellipsoid (its transform scales unevenly), which has no exact volume here; "
                     "exact fractions exist for balls and closed meshes; use --fill or --sdf for ellipsoids");
  return {transformPoint(s.transform, s.center), std::sqrt(s2) * s.radius};
}

std::vector<Ball> ballsOf(const Scene& scene) {
  std::vector<Ball> balls;
  for (size_t i = 0; i < scene.spheres.size(); ++i) balls.push_back(ballOf(scene.spheres[i], i));
  return balls;
}

// Progress and cancellation shared by the parallel phases: each finished block reports, so the caller is asked at
// least as often as a block takes (a few milliseconds).
struct Progress {
  const FractionOptions& options;
  std::atomic<bool> cancelled{false};
  std::atomic<uint64_t> done{0};
  bool report(double base, double span, uint64_t count, uint64_t total) {
    const uint64_t finished = done += count;
    if (options.progress && !options.progress(base + span * double(finished) / double(std::max<uint64_t>(total, 1))))
      cancelled = true;
    return !cancelled;
  }
  void check() {
    if (cancelled) fail<Error>("volume fractions cancelled");
    done = 0;
  }
};

// tbb::parallel_for over [0, n) in blocks of at most `grain` items (simple_partitioner), each reporting when done:
// the default partitioner hands a thread a whole share of the items, and Ctrl-C waited 6 to 11 s during the
// fractions of a large ball.
template <typename Body>
void forBlocks(size_t n, size_t grain, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), body, tbb::simple_partitioner());
}

struct Crossing {
  double z;  // relative to grid.bounds.lo.z
  int32_t jump;
  int32_t after;  // the winding number just above z
  bool operator<(const Crossing& o) const { return z != o.z ? z < o.z : jump < o.jump; }
};

// The crossings of every vertical cell line that is the (x1, y1) edge of an occupied cell, sorted along the line.
struct LineTable {
  std::vector<uint64_t> keys;  // line a + (nx + 1) b, ascending
  std::vector<size_t> start;   // crossings of keys[g]: crossings[start[g] .. start[g + 1])
  std::vector<Crossing> crossings;
  int minWinding = 0, maxWinding = 0;
  bool unclosed = false;  // some line ends with w != 0: the grid misses triangles of the scene
};

// The triangles of each column of cells (i, j), any k: sorted, each once.
struct ColumnTable {
  std::vector<uint64_t> keys;  // column i + nx j, ascending
  std::vector<size_t> start;   // prims of keys[g]: prims[start[g] .. start[g + 1])
  std::vector<uint32_t> prims;
  std::span<const uint32_t> of(uint64_t column) const {
    const auto it = std::lower_bound(keys.begin(), keys.end(), column);
    if (it == keys.end() || *it != column) return {};
    const size_t g = size_t(it - keys.begin());
    return {prims.data() + start[g], prims.data() + start[g + 1]};
  }
};

ColumnTable columnPrims(const Grid& grid, size_t nTri) {
  tbb::enumerable_thread_specific<std::vector<std::pair<uint64_t, uint32_t>>> locals;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.cellKeys.size(), 1024), [&](const auto& r) {
    auto& out = locals.local();
    for (size_t c = r.begin(); c < r.end(); ++c) {
      const uint64_t column = grid.cellKeys[c] % (uint64_t(grid.dims[0]) * grid.dims[1]);
      for (const uint32_t p : grid.cellPrims(c))
        if (p < nTri) out.push_back({column, p});
    }
  });
  std::vector<std::pair<uint64_t, uint32_t>> pairs;
  for (const auto& local : locals) pairs.insert(pairs.end(), local.begin(), local.end());
  tbb::parallel_sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  ColumnTable t;
  t.prims.reserve(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (i == 0 || pairs[i].first != pairs[i - 1].first) {
      t.keys.push_back(pairs[i].first);
      t.start.push_back(i);
    }
    t.prims.push_back(pairs[i].second);
  }
  t.start.push_back(pairs.size());
  return t;
}

// Which triangles may cross line a + (nx + 1) b: those of the four cell columns around it (a triangle crossing the
// line at height z meets the closed cells there), and those sticking out of the grid (rare: user bounds cutting the
// scene, a box test each). Each list goes to `visit` as a span; a triangle may come more than once.
template <typename Visit>
void forLineCandidates(const Grid& grid, const Scene& scene, const ColumnTable& columns, uint64_t line,
                       const Visit& visit) {
  const uint64_t nx = grid.dims[0], ny = grid.dims[1], a = line % (nx + 1), b = line / (nx + 1);
  for (uint64_t j = b > 0 ? b - 1 : 0; j <= b && j < ny; ++j)
    for (uint64_t i = a > 0 ? a - 1 : 0; i <= a && i < nx; ++i) visit(columns.of(i + nx * j));
  if (grid.outsidePrims.empty()) return;
  const double X = cellBoundary(grid.bounds, grid.dims, 0, int64_t(a));
  const double Y = cellBoundary(grid.bounds, grid.dims, 1, int64_t(b));
  for (const uint32_t& p : grid.outsidePrims) {
    if (p >= scene.triangles.size()) continue;
    const Box box = triangleBounds(scene.triangles[p]);
    if (X >= box.lo.x && X <= box.hi.x && Y >= box.lo.y && Y <= box.hi.y) visit(std::span<const uint32_t>(&p, 1));
  }
}

// The candidates of forLineCandidates, sorted, each once, into `out`.
void linePrims(const Grid& grid, const Scene& scene, const ColumnTable& columns, uint64_t line,
               std::vector<uint32_t>& out) {
  out.clear();
  forLineCandidates(grid, scene, columns, line,
                    [&](std::span<const uint32_t> prims) { out.insert(out.end(), prims.begin(), prims.end()); });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

LineTable buildLines(const Grid& grid, const Scene& scene, const FractionOptions& options, Progress& progress) {
  LineTable table;
  const uint64_t nx1 = uint64_t(grid.dims[0]) + 1;
  std::vector<uint64_t> needed(grid.cellKeys.size());
  tbb::parallel_for(size_t(0), needed.size(), [&](size_t c) {
    const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
    needed[c] = (uint64_t(ijk[0]) + 1) + nx1 * (uint64_t(ijk[1]) + 1);
  });
  tbb::parallel_sort(needed.begin(), needed.end());
  needed.erase(std::unique(needed.begin(), needed.end()), needed.end());
  // Pairs, crossings and the tables: about 4 x 32 bytes per cell-primitive reference, plus 24 per cell.
  const double bytes = 128.0 * double(grid.primIds.size()) + 24.0 * double(grid.cellKeys.size());
  if (bytes > double(options.memoryLimitBytes))
    fail<LimitError>("volume fractions: the cell lines' crossings need ", uint64_t(bytes) >> 20, " MiB, more than the ",
                     options.memoryLimitBytes >> 20, " MiB allowed");
  const ColumnTable columns = columnPrims(grid, scene.triangles.size());
  // Each line's slots: its candidates counted with repeats, a bound on its crossings (compacted to them below).
  table.keys = std::move(needed);
  table.start.assign(table.keys.size() + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, table.keys.size(), 256), [&](const auto& r) {
    for (size_t g = r.begin(); g < r.end(); ++g)
      forLineCandidates(grid, scene, columns, table.keys[g],
                        [&](std::span<const uint32_t> prims) { table.start[g + 1] += prims.size(); });
  });
  tbb::enumerable_thread_specific<std::vector<uint32_t>> scratch;
  for (size_t g = 0; g < table.keys.size(); ++g) table.start[g + 1] += table.start[g];
  table.crossings.resize(table.start.back());
  std::vector<size_t> counts(table.keys.size());
  std::atomic<int> minW{0}, maxW{0};
  std::atomic<bool> unclosed{false};
  forBlocks(table.keys.size(), 256, [&](const auto& r) {
    if (progress.cancelled) return;
    for (size_t g = r.begin(); g < r.end(); ++g) {
      const double X = cellBoundary(grid.bounds, grid.dims, 0, int64_t(table.keys[g] % nx1));
      const double Y = cellBoundary(grid.bounds, grid.dims, 1, int64_t(table.keys[g] / nx1));
      Crossing* out = table.crossings.data() + table.start[g];
      size_t n = 0;
      std::vector<uint32_t>& prims = scratch.local();
      linePrims(grid, scene, columns, table.keys[g], prims);
      for (const uint32_t p : prims)
        if (const auto c = volume::lineCrossing(scene.triangles[p], X, Y, grid.bounds.lo.z))
          out[n++] = {c->z, c->jump, 0};
      std::sort(out, out + n);
      int w = 0, lo = 0, hi = 0;
      for (size_t i = 0; i < n; ++i) {
        out[i].after = w += out[i].jump;
        // Only between distinct heights: crossings at one z (a vertex on the line, touching shells) bound an
        // interval of length 0, whose w does not count.
        if (i + 1 < n && out[i + 1].z == out[i].z) continue;
        lo = std::min(lo, w);
        hi = std::max(hi, w);
      }
      counts[g] = n;
      if (w != 0) unclosed = true;
      for (int m = minW; lo < m && !minW.compare_exchange_weak(m, lo);) {
      }
      for (int m = maxW; hi > m && !maxW.compare_exchange_weak(m, hi);) {
      }
    }
    progress.report(0, 0.3, r.size(), table.keys.size());
  });
  progress.check();
  // Compact: each line keeps only the triangles that cross it.
  size_t used = 0;
  for (size_t g = 0; g < table.keys.size(); ++g) {
    std::copy_n(table.crossings.begin() + table.start[g], counts[g], table.crossings.begin() + used);
    table.start[g] = used;
    used += counts[g];
  }
  table.start.back() = used;
  table.crossings.resize(used);
  table.minWinding = minW;
  table.maxWinding = maxW;
  table.unclosed = unclosed;
  return table;
}

// The integral of w along the cell's edge (x1, y1, z in (z0, z1]), from its line's sorted crossings.
double edgeIntegral(const LineTable& lines, uint64_t key, double z0, double z1) {
  const auto it = std::lower_bound(lines.keys.begin(), lines.keys.end(), key);
  if (it == lines.keys.end() || *it != key) return 0;  // no triangle near the line: w = 0 along it
  const size_t g = size_t(it - lines.keys.begin());
  const Crossing* first = lines.crossings.data() + lines.start[g];
  const Crossing* last = lines.crossings.data() + lines.start[g + 1];
  const Crossing* c = std::upper_bound(first, last, z0, [](double z, const Crossing& x) { return z < x.z; });
  double sum = (c == first ? 0 : (c - 1)->after) * (z1 - z0);
  for (; c != last && c->z <= z1; ++c) sum += c->jump * (z1 - c->z);
  return sum;
}

// Cells whose solids the method cannot add: a ball with the mesh, or two overlapping balls. The first such cell in
// cellKeys order is reported, whatever the thread count.
struct Conflict {
  std::atomic<uint64_t> cell{UINT64_MAX};
  void note(uint64_t c) {
    for (uint64_t m = cell; c < m && !cell.compare_exchange_weak(m, c);) {
    }
  }
};

}  // namespace

void checkVolumeFractionsPossible(const Scene& scene, OverlapMethod method, uint64_t memoryLimitBytes) {
  if (!scene.planes.empty())
    fail<UsageError>("volume fractions: the scene has ", scene.planes.size(),
                     " plane(s), which bound no finite volume; remove the planes (--fill and --sdf leave them out)");
  if (method == OverlapMethod::Center)
    fail<UsageError>(
        "volume fractions need every primitive that touches a cell: voxelize with --method exact, "
        "sat or bbox, not center");
  for (size_t i = 0; i < scene.spheres.size(); ++i) ballOf(scene.spheres[i], i);
  if (scene.triangles.empty()) return;
  const double weld = 48.0 * double(scene.triangles.size());
  if (weld > double(memoryLimitBytes))
    fail<LimitError>("volume fractions: checking that the mesh is closed needs ", uint64_t(weld) >> 20,
                     " MiB, more than the ", memoryLimitBytes >> 20, " MiB allowed");
  uint64_t openEdges = 0;
  const std::vector<OpenBoundary> seams =
      openBoundaries({scene.triangles.data(), scene.triangles.size()}, &openEdges, 0);
  if (openEdges > 0)
    fail<UsageError>("volume fractions need closed surfaces: the mesh has ", openEdges,
                     " open edges; --fill's winding number decides its solid, but no exact volume exists; close the "
                     "mesh or use --sdf");
  if (!seams.empty())
    fail<UsageError>("volume fractions need a consistently oriented mesh: its orientation flips along ", seams.size(),
                     " seam(s); --fill decides its solid, but no exact volume exists; orient the faces "
                     "consistently or use --sdf");
}

FillOptions fillForFractions(FillOptions options) {
  options.rule = FillRule::WindingNumber;
  options.windingOnly = true;
  return options;
}

namespace {

std::vector<double> framedVolumeFractions(const Grid& grid, const Scene& scene, const FractionOptions& options);

}  // namespace

// Computed in the power-of-two frame of the scene and the bounds together (docs/limits.md "Numeric domain"): cell
// volumes and the integrals' products neither overflow at 1e120 nor underflow at 1e-120, and a scene's fractions
// at scale 2^k equal its fractions at scale 1.
std::vector<double> volumeFractions(const Grid& grid, const Scene& scene, const FractionOptions& options) {
  checkVolumeFractionsPossible(scene, grid.method, options.memoryLimitBytes);
  const PowerOfTwoFrame frame = fractionFrame(scene, grid.bounds);
  checkNumericDomain(scene, grid.bounds, grid.dims, frame, false, "volume fractions");
  std::vector<double> fractions;
  if (frame.identity()) {
    fractions = framedVolumeFractions(grid, scene, options);
  } else {
    Grid framed = grid;  // the cells as they are, the bounds in the frame
    framed.bounds = frame.toFrame(grid.bounds);
    fractions = framedVolumeFractions(framed, sceneInFrame(scene, frame), options);
  }
  // The grid file's reader refuses anything else: refuse it here, before a file is written (issue 45).
  for (size_t c = 0; c < fractions.size(); ++c)
    if (!(fractions[c] >= 0 && fractions[c] <= 1)) {
      const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
      fail<InputError>("volume fractions: cell (", ijk[0], ", ", ijk[1], ", ", ijk[2], ") got ", fractions[c],
                       ": the scene lies outside the numeric domain of docs/limits.md");
    }
  return fractions;
}

namespace {

std::vector<double> framedVolumeFractions(const Grid& grid, const Scene& scene, const FractionOptions& options) {
  const std::vector<Ball> balls = ballsOf(scene);
  Progress progress{options};
  const size_t nTri = scene.triangles.size();
  LineTable lines;
  if (nTri > 0) lines = buildLines(grid, scene, options, progress);
  if (lines.unclosed)
    fail<UsageError>(
        "volume fractions: the grid does not hold every triangle of the scene (a line through it ends "
        "inside the mesh); voxelize this scene again");
  if (lines.maxWinding > 1 || lines.minWinding < -1 || (lines.maxWinding > 0 && lines.minWinding < 0))
    fail<UsageError>(
        "volume fractions need a mesh whose parts neither overlap nor nest with opposite orientations: "
        "its winding number reaches ",
        lines.maxWinding > 1 ? lines.maxWinding : lines.minWinding,
        "; --fill decides its solid, but no exact volume exists; remove the overlaps or use --sdf");
  const double orientation = lines.minWinding < 0 ? -1 : 1;  // a mesh oriented inward encloses w = -1
  const uint64_t nx1 = uint64_t(grid.dims[0]) + 1;
  std::vector<double> fractions(grid.cellKeys.size());
  Conflict conflict;
  // Blocks of 64 cells: a cell cut by a ball costs up to a few hundred microseconds of quadrature.
  forBlocks(grid.cellKeys.size(), 64, [&](const auto& r) {
    if (progress.cancelled) return;
    std::vector<const Triangle*> tris;
    std::vector<uint32_t> cellBalls;
    for (size_t c = r.begin(); c < r.end(); ++c) {
      const auto ijk = cellIndex(grid.dims, grid.cellKeys[c]);
      const Box box = cellBox(grid, ijk[0], ijk[1], ijk[2]);
      const CellPlanes planes{{box.lo.x, box.lo.y, box.lo.z}, {box.hi.x, box.hi.y, box.hi.z}};
      tris.clear();
      cellBalls.clear();
      for (const uint32_t p : grid.cellPrims(c))
        if (p < nTri)
          tris.push_back(&scene.triangles[p]);
        else if (p - nTri < balls.size())
          cellBalls.push_back(uint32_t(p - nTri));
      double v = 0;
      if (nTri > 0) {
        const uint64_t key = (uint64_t(ijk[0]) + 1) + nx1 * (uint64_t(ijk[1]) + 1);
        const double edge = edgeIntegral(lines, key, box.lo.z - grid.bounds.lo.z, box.hi.z - grid.bounds.lo.z);
        v = orientation * volume::cellMeshVolume(tris, planes, edge);
      }
      if (!cellBalls.empty() && (!tris.empty() || v != 0)) conflict.note(c);
      for (size_t i = 0; i < cellBalls.size(); ++i) {
        const Ball& b = balls[cellBalls[i]];
        for (size_t j = 0; j < i; ++j) {
          const Ball& o = balls[cellBalls[j]];
          if (length(b.center - o.center) < b.radius + o.radius) conflict.note(c);
        }
        v += volume::ballBoxVolume(b.center, b.radius, box);
      }
      const double cellVolume = (box.hi.x - box.lo.x) * (box.hi.y - box.lo.y) * (box.hi.z - box.lo.z);
      fractions[c] = std::clamp(v / cellVolume, 0.0, 1.0);
    }
    progress.report(0.3, 0.7, r.size(), grid.cellKeys.size());
  });
  progress.check();
  if (conflict.cell != UINT64_MAX) {
    const auto ijk = cellIndex(grid.dims, grid.cellKeys[conflict.cell]);
    fail<UsageError>("volume fractions: cell (", ijk[0], ", ", ijk[1], ", ", ijk[2],
                     ") holds a sphere together with the mesh or with another sphere it overlaps; overlapping solids "
                     "have no exact volume here; keep the solids apart or use --fill");
  }
  return fractions;
}

}  // namespace

}  // namespace vox
