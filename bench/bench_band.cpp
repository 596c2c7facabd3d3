// The narrow band's two routes (libvox/src/distance/band_scan.h): the boxes of issue 38 against the scan
// conversion, on the same grid as `vox-voxelize MESH --res N --sdf 3`, routes alternating, best of --runs each; the
// process's CPU time as well as the wall time, since this shared machine's wall clock is noisy. Checks that the two
// bands are equal bit for bit.
//   build/bench/bench_band [--runs N] [--threads T] [--res N ...] [MESH]   (default: the 69k bunny at 256)
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>

#include "bench_options.h"
#include "distance/band_scan.h"
#include "vox/import/import.h"
#include "vox/voxelize/voxelize.h"

namespace {

double cpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  const vox::bench::BenchOptions options =
      vox::bench::parseBenchOptions(argc, argv, {3, 2, {}, std::string(VOX_SEED_DIR) + "/meshes/bun_zipper.ply"},
                                    [](const std::string&, const char*) { return false; });
  std::vector<uint32_t> resolutions = options.resolutions;
  if (resolutions.empty()) resolutions = {256};
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(options.threads));
  tbb::parallel_for(0, options.threads, [](int) {});
  const vox::Scene scene = vox::loadScene(options.mesh);
  std::printf("%s: %zu triangles, %d threads, best of %d, routes alternating\n", options.mesh.c_str(),
              scene.triangles.size(), options.threads, options.runs);
  for (const uint32_t res : resolutions) {
    vox::VoxelizeOptions vo;
    vo.resolution = res;
    const vox::Grid grid = vox::planGrid(scene, vox::withCubicCells(scene, vo));
    double wall[2] = {1e30, 1e30}, cpu[2] = {1e30, 1e30};
    vox::SdfBand bands[2];
    for (int r = 0; r < options.runs; ++r)
      for (int route = 0; route < 2; ++route) {
        const auto start = vox::bench::Clock::now();
        const double cpu0 = cpuSeconds();
        bands[route] = vox::band::signedDistanceBand(grid, scene, {},
                                                     route == 0 ? vox::band::Route::kBoxes : vox::band::Route::kScan);
        cpu[route] = std::min(cpu[route], cpuSeconds() - cpu0);
        wall[route] = std::min(wall[route], vox::bench::seconds(start));
      }
    const bool same =
        bands[0].keys == bands[1].keys && bands[0].values.size() == bands[1].values.size() &&
        std::memcmp(bands[0].values.data(), bands[1].values.data(), bands[0].values.size() * sizeof(double)) == 0;
    std::printf("res %u: %zu cells; boxes %.3f s wall, %.3f s cpu; scan %.3f s wall, %.3f s cpu; %s\n", res,
                bands[0].keys.size(), wall[0], cpu[0], wall[1], cpu[1], same ? "equal bit for bit" : "DIFFERENT");
    if (!same) return 1;
  }
  return 0;
}
