// The volume error of binary voxelizations against the exact volume fractions (issue 38, docs/volume-error.md): for
// each closed scene, resolution and overlap method, the volume of the cells a user would count as the solid
// (occupied or filled, the fill's interior alone, and the cells at least half inside by their fraction), against
// the fractions' exact total. Prints CSV on stdout; bench/volume_error.py runs it and draws the page.
// Usage: volume_error [--threads T] [--res N ...] SCENE...
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "vox/core/compensated_sum.h"
#include "vox/import/import.h"
#include "vox/volume/fractions.h"
#include "vox/voxelize/fill.h"
#include "vox/voxelize/voxelize.h"

namespace {

double cellVolume(const vox::Grid& g, uint64_t key) {
  const auto ijk = vox::cellIndex(g.dims, key);
  const vox::Box b = vox::cellBox(g, ijk[0], ijk[1], ijk[2]);
  return (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y) * (b.hi.z - b.lo.z);
}

double solidVolume(const vox::Grid& g) {
  vox::CompensatedSum sum;
  for (const vox::CellRun& run : g.solidRuns)
    for (uint64_t key = run.first; key < run.first + run.count; ++key) sum.add(cellVolume(g, key));
  return sum.value();
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// One scene at one resolution: the exact volume from the `exact` grid's fractions, then each method's counts.
void measure(const std::string& name, const vox::Scene& scene, uint32_t res) {
  vox::VoxelizeOptions o;
  o.resolution = res;
  vox::Grid exact = vox::voxelizeScene(scene, o);
  vox::fillSolid(exact, scene, vox::fillForFractions({}));
  auto start = std::chrono::steady_clock::now();
  const std::vector<double> f = vox::volumeFractions(exact, scene);
  const double fractionSeconds = seconds(start);
  const double interior = solidVolume(exact);
  vox::CompensatedSum total, half;
  total.add(interior);
  half.add(interior);
  for (size_t c = 0; c < f.size(); ++c) {
    const double v = cellVolume(exact, exact.cellKeys[c]);
    total.add(f[c] * v);
    if (f[c] >= 0.5) half.add(v);
  }
  const double truth = total.value();
  const auto row = [&](const char* method, const char* counted, double volume, double s) {
    std::printf("%s,%zu,%u,%u,%u,%u,%s,%s,%.17g,%.17g,%.6e,%.6f\n", name.c_str(),
                scene.triangles.size() + scene.spheres.size(), res, exact.dims[0], exact.dims[1], exact.dims[2], method,
                counted, volume, truth, (volume - truth) / truth, s);
  };
  row("fractions", "exact", truth, fractionSeconds);
  row("fractions", "at least half", half.value(), fractionSeconds);
  row("exact", "interior", interior, 0);
  for (const char* method : {"exact", "sat", "bbox", "center"}) {
    o.method = vox::parseMethod(method);
    start = std::chrono::steady_clock::now();
    vox::Grid g = vox::voxelizeScene(scene, o);
    vox::fillSolid(g, scene);
    const double s = seconds(start);
    vox::CompensatedSum cells;
    for (const uint64_t key : g.cellKeys) cells.add(cellVolume(g, key));
    row(method, "occupied and filled", cells.value() + solidVolume(g), s);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int threads = 2;
  std::vector<uint32_t> resolutions;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (a == "--res" && i + 1 < argc)
      resolutions.push_back(uint32_t(std::atoi(argv[++i])));
    else
      scenes.push_back(a);
  }
  if (resolutions.empty()) resolutions = {16, 32, 64, 128, 256};
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  std::printf("scene,primitives,res,nx,ny,nz,method,counted,volume,exact_volume,relative_error,seconds\n");
  for (const std::string& path : scenes) {
    const vox::Scene scene = vox::loadScene(path);
    const std::string name = path.substr(path.find_last_of('/') + 1);
    for (const uint32_t res : resolutions) measure(name, scene, res);
  }
  return 0;
}
