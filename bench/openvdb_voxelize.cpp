// Baseline for the voxelizer benchmark: OpenVDB 10's meshToUnsignedDistanceField with a band of one voxel, on the
// same triangles and the same voxel size as `vox-voxelize --res N`. Prints name: value lines like vox-voxelize --stats.
// Usage: openvdb_voxelize SCENE RES [THREADS]
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>

#include "vox/import/import.h"
#include "vox/voxelize/voxelize.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: openvdb_voxelize SCENE RES [THREADS]\n");
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, argc > 3 ? std::atoi(argv[3]) : 2);
  openvdb::initialize();
  const vox::Scene scene = vox::loadScene(argv[1]);
  vox::VoxelizeOptions options;
  options.resolution = uint32_t(std::atoi(argv[2]));
  const vox::Grid plan = vox::planGrid(scene, options);
  const double voxel = (plan.bounds.hi.x - plan.bounds.lo.x) / plan.dims[0];

  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  points.reserve(scene.triangles.size() * 3);
  for (const auto& t : scene.triangles) {
    const auto base = uint32_t(points.size());
    for (const auto& v : t.v) points.emplace_back(float(v.x), float(v.y), float(v.z));
    triangles.emplace_back(base, base + 1, base + 2);
  }
  const auto xform = openvdb::math::Transform::createLinearTransform(voxel);
  const auto t0 = std::chrono::steady_clock::now();
  const auto grid =
      openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xform, points, triangles, quads, 1.0f);
  const auto t1 = std::chrono::steady_clock::now();
  // Voxels within one voxel of the surface: the band OpenVDB marks.
  uint64_t marked = 0;
  for (auto it = grid->cbeginValueOn(); it; ++it) marked += it.getValue() <= float(voxel) ? 1 : 0;
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  std::printf(
      "voxel_size: %.9g\nactive_voxels: %llu\nmarked_voxels: %llu\nvoxelize_seconds: %.6f\ntotal_seconds: "
      "%.6f\npeak_memory_mb: %.1f\n",
      voxel, (unsigned long long)grid->activeVoxelCount(), (unsigned long long)marked,
      std::chrono::duration<double>(t1 - t0).count(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
      double(usage.ru_maxrss) / 1024.0);
  return 0;
}
