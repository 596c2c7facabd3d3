// Baseline for `vox-voxelize --sdf`: OpenVDB 10's meshToLevelSet on the same welded mesh, voxel size and half-width,
// its voxel centres on our cell centres. Prints name: value lines like vox-voxelize --stats. With a grid file made
// by `vox-voxelize SCENE --res RES --sdf HALF`, also compares the two fields on the cells both hold: OpenVDB's sign
// errors (ours are exact: tests/distance_test.cpp) and the largest difference of the magnitudes, in voxels.
// Usage: openvdb_sdf SCENE RES [HALF] [THREADS] [GRID.vgrid]
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "exact_side.h"
#include "vox/distance/sdf.h"
#include "vox/import/import.h"
#include "vox/io/grid_file.h"
#include "vox/voxelize/open_edges.h"

namespace {

// The scene's triangles with equal positions welded, as a mesh file holds them (meshToLevelSet needs a connected
// surface for its sign). Float, as OpenVDB takes them.
void weld(const vox::Scene& scene, std::vector<openvdb::Vec3s>& points, std::vector<openvdb::Vec3I>& triangles) {
  std::map<std::array<double, 3>, uint32_t> index;
  for (const auto& t : scene.triangles) {
    uint32_t ids[3];
    for (int c = 0; c < 3; ++c) {
      const auto [it, added] = index.emplace(std::array<double, 3>{t.v[c].x, t.v[c].y, t.v[c].z}, points.size());
      if (added) points.emplace_back(float(t.v[c].x), float(t.v[c].y), float(t.v[c].z));
      ids[c] = it->second;
    }
    triangles.emplace_back(ids[0], ids[1], ids[2]);
  }
}

double quantile(std::vector<double>& v, double q) {
  if (v.empty()) return 0;
  const auto at = v.begin() + std::ptrdiff_t(q * double(v.size() - 1));
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

// OpenVDB's field against ours on the band cells both hold; where the signs differ and the mesh is closed, CGAL's
// exact inside test says who is right.
void compare(const openvdb::FloatGrid& vdb, const vox::Grid& ours, const vox::Scene& scene, double voxel) {
  std::unique_ptr<vox::testing::ExactSide> cgal;
  if (vox::countOpenEdges({scene.triangles.data(), scene.triangles.size()}) == 0)
    cgal = std::make_unique<vox::testing::ExactSide>(
        std::vector<vox::Triangle>(scene.triangles.begin(), scene.triangles.end()));
  uint64_t cgalAgreesWithUs = 0, cgalAgreesWithOpenVdb = 0;
  const auto acc = vdb.getConstAccessor();
  uint64_t both = 0, insideAsOutside = 0, outsideAsInside = 0;
  std::vector<double> differences;
  for (size_t b = 0; b < ours.sdfKeys.size(); ++b) {
    const auto ijk = vox::cellIndex(ours.dims, ours.sdfKeys[b]);
    float v;
    if (!acc.probeValue(openvdb::Coord(int(ijk[0]), int(ijk[1]), int(ijk[2])), v)) continue;
    ++both;
    const double o = ours.sdfValues[b];
    const bool disagree = (o < 0 && v >= 0) || (o > 0 && v < 0);
    if (o < 0 && v >= 0) ++insideAsOutside;
    if (o > 0 && v < 0) ++outsideAsInside;
    if (disagree && cgal)
      ++(((cgal->side(vox::cellCentre(ours, ours.sdfKeys[b])) < 0) == (o < 0)) ? cgalAgreesWithUs
                                                                               : cgalAgreesWithOpenVdb);
    differences.push_back(std::fabs(std::fabs(double(v)) - std::fabs(o)) / voxel);
  }
  std::printf(
      "compared_cells: %llu\nopenvdb_sign_errors: %llu (inside called outside: %llu, outside called inside: "
      "%llu)\nmagnitude_difference_voxels: median %.3g, 99th percentile %.3g, worst %.3g\n",
      (unsigned long long)both, (unsigned long long)(insideAsOutside + outsideAsInside),
      (unsigned long long)insideAsOutside, (unsigned long long)outsideAsInside, quantile(differences, 0.5),
      quantile(differences, 0.99), quantile(differences, 1));
  if (cgal)
    std::printf("cgal_on_the_disagreements: agrees with libvox %llu, with OpenVDB %llu\n",
                (unsigned long long)cgalAgreesWithUs, (unsigned long long)cgalAgreesWithOpenVdb);
  else
    std::printf("cgal_on_the_disagreements: not asked (the mesh is open)\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: openvdb_sdf SCENE RES [HALF] [THREADS] [GRID.vgrid]\n");
    return 1;
  }
  const auto start = std::chrono::steady_clock::now();
  const float half = argc > 3 ? std::strtof(argv[3], nullptr) : 3.0f;
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, argc > 4 ? std::atoi(argv[4]) : 2);
  openvdb::initialize();
  const vox::Scene scene = vox::loadScene(argv[1]);
  vox::VoxelizeOptions options;
  options.resolution = uint32_t(std::atoi(argv[2]));
  const vox::Grid plan = vox::planGrid(scene, vox::withCubicCells(scene, options));  // vox-voxelize --sdf's cells
  const double voxel = (plan.bounds.hi.x - plan.bounds.lo.x) / plan.dims[0];
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  weld(scene, points, triangles);
  auto xform = openvdb::math::Transform::createLinearTransform(voxel);
  xform->postTranslate(openvdb::Vec3d(plan.bounds.lo.x, plan.bounds.lo.y, plan.bounds.lo.z) + 0.5 * voxel);
  const auto t0 = std::chrono::steady_clock::now();
  const auto grid = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, points, triangles, half);
  const auto t1 = std::chrono::steady_clock::now();
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  std::printf("voxel_size: %.9g\nactive_voxels: %llu\nsdf_seconds: %.6f\ntotal_seconds: %.6f\npeak_memory_mb: %.1f\n",
              voxel, (unsigned long long)grid->activeVoxelCount(), std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              double(usage.ru_maxrss) / 1024.0);
  if (argc > 5) compare(*grid, vox::readGridFile(argv[5]).grid, scene, voxel);
  return 0;
}
