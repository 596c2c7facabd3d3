// Distances beyond the band (issue 38), in C++ so that `perf` sees them: Grid.distance's pointDistances on P points
// uniform in the mesh's bounding box (unsigned, then signed), and libvox.sdf's dense field at each --res (voxelize,
// fill and denseSignedDistances timed apart). Best of --runs each, on --threads threads (default 2). The Open3D
// ratio is bench/distance_bench.py's; this one says where the time goes.
//   build/bench/bench_distance [--runs N] [--threads T] [--points P] [--res N ...] [MESH]   (default: the 69k bunny)
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "bench_options.h"
#include "vox/distance/nearest.h"
#include "vox/distance/queries.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace {

using vox::bench::Clock;
using vox::bench::seconds;

template <typename F>
double best(int runs, const F& run) {
  double fastest = 1e30;
  for (int r = 0; r < runs; ++r) {
    const auto start = Clock::now();
    run();
    fastest = std::min(fastest, seconds(start));
  }
  return fastest;
}

}  // namespace

int main(int argc, char** argv) {
  size_t pointCount = 1000000;
  const vox::bench::BenchOptions options =
      vox::bench::parseBenchOptions(argc, argv, {3, 2, {}, std::string(VOX_SEED_DIR) + "/meshes/bun_zipper.ply"},
                                    [&](const std::string& flag, const char* value) {
                                      if (flag != "--points") return false;
                                      pointCount = size_t(std::atoll(value));
                                      return true;
                                    });
  const int runs = options.runs, threads = options.threads;
  const std::string& path = options.mesh;
  std::vector<uint32_t> resolutions = options.resolutions;
  if (resolutions.empty()) resolutions = {64, 128};
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  tbb::parallel_for(0, threads, [](int) {});  // the worker threads started before any clock
  const vox::Scene scene = vox::loadScene(path);
  const vox::Box box = *vox::sceneBounds(scene);
  std::printf("%s: %zu triangles, %d threads, best of %d\n", path.c_str(), scene.triangles.size(), threads, runs);

  std::mt19937_64 random(1);
  std::vector<double> points(3 * pointCount);
  for (size_t i = 0; i < points.size(); ++i) {
    std::uniform_real_distribution<double> along(box.lo[int(i % 3)], box.hi[int(i % 3)]);
    points[i] = along(random);
  }
  std::vector<double> distance(pointCount), closest(3 * pointCount);
  std::vector<int64_t> primitive(pointCount);
  const vox::PointDistanceOutput out{distance, primitive, closest};
  const double build = best(runs, [&] { const vox::NearestPrimitive tree(scene); });
  std::printf("NearestPrimitive build: %.3f s\n", build);
  for (const bool signedDistance : {false, true}) {
    const double s = best(runs, [&] { vox::pointDistances(scene, points, signedDistance, out); });
    std::printf("pointDistances %s: %zu points, %.3f s, %.0f points/s\n", signedDistance ? "signed" : "unsigned",
                pointCount, s, double(pointCount) / s);
  }

  for (const uint32_t res : resolutions) {
    vox::VoxelizeOptions o;
    o.resolution = res;
    o = vox::withCubicCells(scene, o);
    vox::Grid grid;
    const double voxelize = best(runs, [&] { grid = vox::voxelizeScene(scene, o); });
    const double fill = best(runs, [&] { vox::fillSolid(grid, scene); });
    std::vector<double> field(grid.cellCount());
    const std::array<uint64_t, 3> strides{uint64_t(grid.dims[1]) * grid.dims[2], grid.dims[2], 1};
    const double dense = best(runs, [&] { vox::denseSignedDistances(grid, scene, field, strides); });
    std::printf("sdf %u (%u x %u x %u): voxelize %.3f s, fill %.3f s, dense %.3f s, total %.3f s, %.0f cells/s\n", res,
                grid.dims[0], grid.dims[1], grid.dims[2], voxelize, fill, dense, voxelize + fill + dense,
                double(field.size()) / (voxelize + fill + dense));
  }
  return 0;
}
