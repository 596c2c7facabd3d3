#include "report.h"

#include <sys/resource.h>

#include <cstdio>

#include "vox/core/tool.h"

namespace vox::voxelize_tool {

namespace {

double peakMemoryMb() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;
}

}  // namespace

void reportFill(const Options& opt, const FillReport& report) {
  if (opt.common.quiet) return;
  std::fprintf(stderr, "vox-voxelize: fill: %s\n", describeFill(report).c_str());
  if (const std::string w = fillWarning(report); !w.empty())
    std::fputs(warningLine("vox-voxelize", opt.scene + ": fill: " + w).c_str(), stderr);
}

void printGridStats(const Scene& scene, const Grid& grid, const VoxelizeStats& stats, const GridTimes& times) {
  std::fprintf(stderr,
               "triangles: %zu\nspheres: %zu\nplanes: %zu\ndegenerate_triangles: %llu\ndims: %u %u %u\nmethod: %s\n"
               "cells_tested: %llu\nexact_fallbacks: %llu\noccupied_cells: %zu\nsolid_cells: %llu\nreferences: %zu\n"
               "read_seconds: %.6f\nvoxelize_seconds: %.6f\nwrite_seconds: %.6f\nsync_seconds: %.6f\n"
               "total_seconds: %.6f\npeak_memory_mb: %.1f\n",
               scene.triangles.size(), scene.spheres.size(), scene.planes.size(),
               (unsigned long long)stats.degenerateTriangles, grid.dims[0], grid.dims[1], grid.dims[2],
               methodName(grid.method).c_str(), (unsigned long long)stats.cellsTested,
               (unsigned long long)stats.exactFallbacks, grid.occupiedCount(), (unsigned long long)grid.solidCount(),
               grid.referenceCount(), times.read, stats.seconds, times.write.writeSeconds, times.write.syncSeconds,
               times.total, peakMemoryMb());
}

void printSetStats(const Scene& scene, const GridSetManifest& set, const VoxelizeStats& stats, double totalSeconds) {
  uint64_t occupied = 0, references = 0, solid = 0;
  for (const BrickEntry& e : set.entries) {
    occupied += e.occupied;
    references += e.references;
    solid += e.solid;
  }
  std::fprintf(stderr,
               "triangles: %zu\nspheres: %zu\nplanes: %zu\ndims: %u %u %u\nmethod: %s\nbricks: %u %u %u\n"
               "brick_files: %zu\ncells_tested: %llu\nexact_fallbacks: %llu\noccupied_cells: %llu\n"
               "solid_cells: %llu\nreferences: %llu\nvoxelize_seconds: %.6f\ntotal_seconds: %.6f\n"
               "peak_memory_mb: %.1f\n",
               scene.triangles.size(), scene.spheres.size(), scene.planes.size(), set.dims[0], set.dims[1], set.dims[2],
               methodName(set.method).c_str(), set.bricks[0], set.bricks[1], set.bricks[2], set.entries.size(),
               (unsigned long long)stats.cellsTested, (unsigned long long)stats.exactFallbacks,
               (unsigned long long)occupied, (unsigned long long)solid, (unsigned long long)references, stats.seconds,
               totalSeconds, peakMemoryMb());
}

}  // namespace vox::voxelize_tool
