// Issue 46's lead for volume fractions, as a prototype to measure (not the library's route: its answers differ from
// volumeFractions' in the last bits, and it makes no exact decisions for faces on cell planes). Per row of cells
// (j, k): each triangle of the row is clipped to the row's yz column once, the fragment is cut along x into the
// cells it spans, each piece adds its flux of (x - x0, 0, 0) to its cell and its yz-projected signed area to the
// row's running face integral, and one prefix sum along the row gives every cell's integral over its high-x face:
// work grows with fragments plus cells instead of (cell, triangle) pairs times six clip planes plus a section and
// a line per cell. Prints the fill's, today's fractions' and the prototype's times (alternating, best of --runs)
// and the prototype's largest difference from today's fractions.
//   build-bench/bench/volume_rows [--runs N] [--threads T] [--res N ...] [MESH]   (default: the course's 5k bunny)
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_options.h"
#include "vox/import/import.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"
#include "volume/mesh_cell_volume.h"

namespace {

using vox::Vec3;
using vox::bench::Clock;
using vox::bench::seconds;

using vox::volume::clipPolygon;
using Poly = vox::volume::Polygon;

struct Scratch {
  std::vector<uint32_t> prims;
  std::vector<double> flux, area;
};

// The fractions of the occupied cells [c0, c1) of one row (same j, k).
void rowFractions(const vox::Grid& grid, const vox::Scene& scene, size_t c0, size_t c1, double orientation, Scratch& s,
                  std::vector<double>& out) {
  const size_t nTri = scene.triangles.size();
  const auto first = vox::cellIndex(grid.dims, grid.cellKeys[c0]);
  const uint32_t j = first[1], k = first[2], ilo = first[0];
  const uint32_t ihi = vox::cellIndex(grid.dims, grid.cellKeys[c1 - 1])[0];
  s.prims.clear();
  for (size_t c = c0; c < c1; ++c)
    for (const uint32_t p : grid.cellPrims(c))
      if (p < nTri) s.prims.push_back(p);
  std::sort(s.prims.begin(), s.prims.end());
  s.prims.erase(std::unique(s.prims.begin(), s.prims.end()), s.prims.end());
  const size_t n = ihi - ilo + 1;
  s.flux.assign(n, 0);
  s.area.assign(n, 0);
  const auto boundary = [&](int axis, int64_t i) { return vox::cellBoundary(grid.bounds, grid.dims, axis, i); };
  const double y0 = boundary(1, j), y1 = boundary(1, j + 1), z0 = boundary(2, k), z1 = boundary(2, k + 1);
  const double xLo = grid.bounds.lo.x, hx = (grid.bounds.hi.x - xLo) / grid.dims[0];
  for (const uint32_t p : s.prims) {
    const vox::Triangle& t = scene.triangles[p];
    Poly poly;
    poly.n = 3;
    for (int v = 0; v < 3; ++v) poly.v[v] = {t.v[v].x, t.v[v].y - y0, t.v[v].z - z0};
    poly = clipPolygon(poly, 1, 0, false);
    if (poly.n > 2) poly = clipPolygon(poly, 1, y1 - y0, true);
    if (poly.n > 2) poly = clipPolygon(poly, 2, 0, false);
    if (poly.n > 2) poly = clipPolygon(poly, 2, z1 - z0, true);
    if (poly.n < 3) continue;
    double xmin = poly.v[0].x, xmax = xmin;
    for (int v = 1; v < poly.n; ++v) xmin = std::min(xmin, poly.v[v].x), xmax = std::max(xmax, poly.v[v].x);
    int64_t i = std::clamp<int64_t>(int64_t(std::floor((xmin - xLo) / hx)), ilo, ihi);
    while (i > ilo && boundary(0, i) > xmin) --i;
    while (i < ihi && boundary(0, i + 1) < xmin) ++i;
    for (;; ++i) {
      const double xa = boundary(0, i), xb = boundary(0, i + 1);
      const bool last = i == ihi || xmax <= xb;
      const Poly piece = last ? poly : clipPolygon(poly, 0, xb, true);
      double f = 0, a = 0;
      for (int v = 1; v + 1 < piece.n; ++v) {
        const Vec3 e = piece.v[v] - piece.v[0], g = piece.v[v + 1] - piece.v[0];
        const double cross = e.y * g.z - e.z * g.y;
        f += cross * ((piece.v[0].x - xa) + (piece.v[v].x - xa) + (piece.v[v + 1].x - xa));
        a += cross;
      }
      s.flux[i - ilo] += f / 6;
      s.area[i - ilo] += a / 2;
      if (last) break;
      poly = clipPolygon(poly, 0, xb, false);
      if (poly.n < 3) break;
    }
  }
  // The face integral at each cell's high x: the integral at the row's low end (0: no triangle before it) less the
  // projected areas crossed so far.
  double face = 0;
  size_t c = c0;
  for (uint32_t i = ilo; i <= ihi; ++i) {
    face -= s.area[i - ilo];
    if (c < c1 && vox::cellIndex(grid.dims, grid.cellKeys[c])[0] == i) {
      const vox::Box b = vox::cellBox(grid, i, j, k);
      const double v = s.flux[i - ilo] + (b.hi.x - b.lo.x) * face;
      const double volume = (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z);
      out[c++] = std::clamp(orientation * v / volume, 0.0, 1.0);
    }
  }
}

std::vector<double> prototypeFractions(const vox::Grid& grid, const vox::Scene& scene, double orientation) {
  std::vector<size_t> rows;  // first cell of each row, then the end
  const uint64_t nx = grid.dims[0];
  for (size_t c = 0; c < grid.cellKeys.size(); ++c)
    if (c == 0 || grid.cellKeys[c] / nx != grid.cellKeys[c - 1] / nx) rows.push_back(c);
  rows.push_back(grid.cellKeys.size());
  std::vector<double> out(grid.cellKeys.size());
  tbb::enumerable_thread_specific<Scratch> scratch;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rows.size() - 1, 16), [&](const auto& r) {
    Scratch& s = scratch.local();
    for (size_t g = r.begin(); g < r.end(); ++g) rowFractions(grid, scene, rows[g], rows[g + 1], orientation, s, out);
  });
  return out;
}

// The per-(cell, triangle) work of today's route without its line table: cellMeshVolume over every occupied cell
// (each triangle clipped to the cell by six planes, and its section by the cell's high-x face). Returns the pairs.
std::atomic<uint64_t> sink{0};

template <typename PerCell>
size_t forEveryCell(const vox::Grid& grid, const vox::Scene& scene, const PerCell& perCell) {
  // The cell planes from one table per axis: the same doubles as cellBox's, without its divisions per cell.
  std::array<std::vector<double>, 3> planes;
  for (int a = 0; a < 3; ++a)
    for (int64_t i = 0; i <= int64_t(grid.dims[a]); ++i)
      planes[a].push_back(vox::cellBoundary(grid.bounds, grid.dims, a, i));
  tbb::enumerable_thread_specific<std::vector<const vox::Triangle*>> lists;
  std::atomic<size_t> pairs{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, grid.cellKeys.size(), 64), [&](const auto& r) {
    std::vector<const vox::Triangle*>& tris = lists.local();
    size_t n = 0;
    double sum = 0;  // returned through `sink`, so that the timed work is not optimised away
    for (size_t c = r.begin(); c < r.end(); ++c) {
      const auto ijk = vox::cellIndex(grid.dims, grid.cellKeys[c]);
      tris.clear();
      for (const uint32_t p : grid.cellPrims(c))
        if (p < scene.triangles.size()) tris.push_back(&scene.triangles[p]);
      n += tris.size();
      sum +=
          perCell(tris, vox::volume::CellPlanes{{planes[0][ijk[0]], planes[1][ijk[1]], planes[2][ijk[2]]},
                                                {planes[0][ijk[0] + 1], planes[1][ijk[1] + 1], planes[2][ijk[2] + 1]}});
    }
    pairs += n;
    if (sum == 12345.678) ++sink;
  });
  return pairs;
}

// The least any route reproducing today's doubles must do per (cell, triangle) pair, even with the x and y clips
// and the section's decisions shared along a z-column: the vertices' z relative to the cell (every clip point's z
// depends on it through its own rounding), the clip by the cell's two z planes and the fan's sum.
double zOnlyFlux(const vox::Triangle& t, const vox::volume::CellPlanes& c) {
  Poly poly;
  poly.n = 3;
  for (int i = 0; i < 3; ++i) poly.v[i] = {t.v[i].x - c.lo[0], t.v[i].y - c.lo[1], t.v[i].z - c.lo[2]};
  poly = clipPolygon(poly, 2, 0, false);
  if (poly.n > 2) poly = clipPolygon(poly, 2, c.hi[2] - c.lo[2], true);
  return vox::volume::polygonFlux(poly);
}

}  // namespace

int main(int argc, char** argv) {
  const vox::bench::BenchOptions options =
      vox::bench::parseBenchOptions(argc, argv, {3, 2, {}, std::string(VOX_SEED_DIR) + "/6837/scenes/bunny_5k.obj"},
                                    [](const std::string&, const char*) { return false; });
  std::vector<uint32_t> resolutions = options.resolutions;
  if (resolutions.empty()) resolutions = {64, 128, 256};
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(options.threads));
  tbb::parallel_for(0, options.threads, [](int) {});
  const vox::Scene scene = vox::loadScene(options.mesh);
  double signedVolume = 0;
  for (const vox::Triangle& t : scene.triangles) signedVolume += dot(t.v[0], cross(t.v[1], t.v[2]));
  const double orientation = signedVolume < 0 ? -1 : 1;
  std::printf("%s: %zu triangles, %d threads, best of %d\n", options.mesh.c_str(), scene.triangles.size(),
              options.threads, options.runs);
  std::printf("%6s %10s %10s %9s %12s %7s %9s %7s %8s %10s %10s %8s %9s %7s\n", "res", "occupied", "pairs", "fill_s",
              "fractions_s", "ratio", "rows_s", "ratio", "max_diff", "diff_cells", "pairs_s", "ratio", "z_only_s",
              "ratio");
  for (const uint32_t res : resolutions) {
    vox::VoxelizeOptions o;
    o.resolution = res;
    vox::Grid grid = vox::voxelizeScene(scene, o);
    double fill = 1e30, today = 1e30, rows = 1e30, pairsTime = 1e30, zTime = 1e30;
    size_t pairs = 0;
    std::vector<double> f, g;
    for (int r = 0; r < options.runs; ++r) {
      auto start = Clock::now();
      vox::fillSolid(grid, scene);
      fill = std::min(fill, seconds(start));
      start = Clock::now();
      f = vox::volumeFractions(grid, scene);
      today = std::min(today, seconds(start));
      start = Clock::now();
      g = prototypeFractions(grid, scene, orientation);
      rows = std::min(rows, seconds(start));
      start = Clock::now();
      pairs = forEveryCell(grid, scene, [&](const std::vector<const vox::Triangle*>& tris, const auto& planes) {
        return vox::volume::cellMeshVolume(tris, planes, 0);
      });
      pairsTime = std::min(pairsTime, seconds(start));
      start = Clock::now();
      forEveryCell(grid, scene, [&](const std::vector<const vox::Triangle*>& tris, const auto& planes) {
        double v = 0;
        for (const vox::Triangle* t : tris) v += zOnlyFlux(*t, planes);
        return v;
      });
      zTime = std::min(zTime, seconds(start));
    }
    double maxDiff = 0;
    size_t differ = 0;
    for (size_t c = 0; c < f.size(); ++c) {
      maxDiff = std::max(maxDiff, std::abs(f[c] - g[c]));
      differ += f[c] != g[c];
    }
    std::printf("%6u %10zu %10zu %9.4f %12.4f %7.2f %9.4f %7.2f %8.1e %10zu %10.4f %8.2f %9.4f %7.2f\n", res,
                grid.cellKeys.size(), pairs, fill, today, today / fill, rows, rows / fill, maxDiff, differ, pairsTime,
                pairsTime / fill, zTime, zTime / fill);
  }
  return 0;
}
