// Volume fractions against the solid fill at the same resolution (issue 38: fractions at most 2x the fill's time).
// Both run on the same voxelized grid, alternating, best of --runs each, on --threads threads (default 2); prints
// both times, the ratio, and the fractions' total volume beside the mesh's signed volume as a check.
//   build/bench/bench_volume [--runs N] [--threads T] [--res N ...] [MESH]   (default: the course's 5k bunny: closed,
//   no self-intersection; the 40k one has 6 intersecting face pairs and is refused)
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <CGAL/Gmpq.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_options.h"
#include "vox/core/compensated_sum.h"
#include "vox/import/import.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace {

using vox::bench::Clock;
using vox::bench::seconds;

double cellVolume(const vox::Grid& g, uint64_t key) {
  const auto ijk = vox::cellIndex(g.dims, key);
  const vox::Box b = vox::cellBox(g, ijk[0], ijk[1], ijk[2]);
  return (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z);
}

// The mesh's signed volume in rationals, rounded once: the reference the fractions' total is compared with.
double exactSignedVolume(const vox::Scene& s) {
  CGAL::Gmpq sum = 0;
  for (const vox::Triangle& t : s.triangles) {
    const CGAL::Gmpq ax = t.v[0].x, ay = t.v[0].y, az = t.v[0].z, bx = t.v[1].x, by = t.v[1].y, bz = t.v[1].z,
                     cx = t.v[2].x, cy = t.v[2].y, cz = t.v[2].z;
    sum += ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx);
  }
  return CGAL::to_double(sum / 6);
}

}  // namespace

int main(int argc, char** argv) {
  const vox::bench::BenchOptions options =
      vox::bench::parseBenchOptions(argc, argv, {5, 2, {}, std::string(VOX_SEED_DIR) + "/6837/scenes/bunny_5k.obj"},
                                    [](const std::string&, const char*) { return false; });
  const int runs = options.runs, threads = options.threads;
  const std::string& path = options.mesh;
  std::vector<uint32_t> resolutions = options.resolutions;
  if (resolutions.empty()) resolutions = {64, 128, 256};
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  tbb::parallel_for(0, threads, [](int) {});  // the worker threads started before any clock
  const vox::Scene scene = vox::loadScene(path);
  std::printf("%s: %zu triangles, %d threads, best of %d\n", path.c_str(), scene.triangles.size(), threads, runs);
  std::printf("%6s %10s %10s %12s %12s %8s %14s\n", "res", "occupied", "solid", "fill_s", "fractions_s", "ratio",
              "volume_error");
  for (const uint32_t res : resolutions) {
    vox::VoxelizeOptions o;
    o.resolution = res;
    vox::Grid grid = vox::voxelizeScene(scene, o);
    double fill = 1e30, fractions = 1e30;
    std::vector<double> f;
    for (int r = 0; r < runs; ++r) {
      auto start = Clock::now();
      vox::fillSolid(grid, scene);
      fill = std::min(fill, seconds(start));
      start = Clock::now();
      f = vox::volumeFractions(grid, scene);
      fractions = std::min(fractions, seconds(start));
    }
    vox::CompensatedSum sum;  // millions of near-equal cell volumes: a plain sum drifts by 1e-10 of the total
    for (size_t c = 0; c < f.size(); ++c) sum.add(f[c] * cellVolume(grid, grid.cellKeys[c]));
    for (const vox::CellRun& run : grid.solidRuns)
      for (uint64_t key = run.first; key < run.first + run.count; ++key) sum.add(cellVolume(grid, key));
    const double total = sum.value(), exact = std::abs(exactSignedVolume(scene));
    std::printf("%6u %10zu %10llu %12.4f %12.4f %8.2f %14.3e\n", res, grid.cellKeys.size(),
                (unsigned long long)grid.solidCount(), fill, fractions, fractions / fill,
                std::abs(total - exact) / exact);
  }
  return 0;
}
