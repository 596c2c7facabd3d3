// The speed-accuracy measurement of issue 5, shared by the benchmark program (bench/tradeoff.cpp) and its small
// mode in the test suite (tests/tradeoff_test.cpp): for each scene, resolution and overlap method, voxelization
// cost, grid size, cells and references added or missed relative to `exact`, and the cost and correctness of
// tracing through that grid (primary and shadow rays, against the brute-force image).
#pragma once

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/import/import.h"
#include "vox/trace/render.h"
#include "vox/voxelize/voxelize.h"

namespace vox::bench {

struct TradeoffScene {
  std::string name;
  Scene scene;
};

struct TradeoffRow {
  std::string scene;
  size_t primitives = 0;
  uint32_t resolution = 0;
  std::array<uint32_t, 3> dims{};
  std::string method;
  double voxelizeSeconds = 0;
  uint64_t tests = 0;
  uint64_t occupied = 0, references = 0;
  uint64_t cellsAdded = 0, cellsMissed = 0;  // occupied cells, relative to exact
  uint64_t refsAdded = 0, refsMissed = 0;    // (cell, primitive) pairs, relative to exact
  double primarySeconds = 0, shadeSeconds = 0;
  double cellsPerRay = 0, testsPerRay = 0;   // over all rays of the shaded image (primary and shadow)
  uint64_t pixelsDiffering = 0, pixels = 0;  // shaded image against the brute-force one
};

// Set differences of two grids, by occupied cell and by (cell, primitive) reference: merges the sorted lists.
inline void compareGrids(const Grid& g, const Grid& exact, TradeoffRow& row) {
  size_t a = 0, b = 0;
  while (a < g.occupiedCount() || b < exact.occupiedCount()) {
    const uint64_t ka = a < g.occupiedCount() ? g.cellKeys[a] : UINT64_MAX;
    const uint64_t kb = b < exact.occupiedCount() ? exact.cellKeys[b] : UINT64_MAX;
    if (ka < kb) {
      ++row.cellsAdded;
      row.refsAdded += g.cellPrims(a).size();
      ++a;
    } else if (kb < ka) {
      ++row.cellsMissed;
      row.refsMissed += exact.cellPrims(b).size();
      ++b;
    } else {
      const auto pa = g.cellPrims(a), pb = exact.cellPrims(b);
      size_t i = 0, j = 0;
      while (i < pa.size() || j < pb.size()) {
        if (j == pb.size() || (i < pa.size() && pa[i] < pb[j])) {
          ++row.refsAdded;
          ++i;
        } else if (i == pa.size() || pb[j] < pa[i]) {
          ++row.refsMissed;
          ++j;
        } else {
          ++i;
          ++j;
        }
      }
      ++a;
      ++b;
    }
  }
}

inline Camera cameraFor(const Scene& scene) {
  if (scene.camera) return *scene.camera;
  const auto b = sceneBounds(scene);
  return defaultCamera(b ? *b : Box{{-1, -1, -1}, {1, 1, 1}});
}

struct TradeoffOptions {
  std::vector<uint32_t> resolutions;  // cells on the longest axis; 0 stands for the default heuristic
  std::vector<OverlapMethod> methods{OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox,
                                     OverlapMethod::Center};
  uint32_t imageSize = 256;
  bool trace = true;
};

inline double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

inline std::vector<TradeoffRow> measureTradeoff(const TradeoffScene& ts, const TradeoffOptions& options) {
  std::vector<TradeoffRow> rows;
  const Scene& scene = ts.scene;
  RenderOptions ro;
  ro.width = ro.height = options.imageSize;
  ro.camera = cameraFor(scene);
  ro.mode = RenderMode::Shade;
  Image brute;
  if (options.trace) {
    // Brute force needs a grid object only for its bounds; an empty one will do.
    VoxelizeOptions none;
    none.dims = std::array<uint32_t, 3>{1, 1, 1};
    Grid empty = planGrid(scene, none);
    const Accel accel = buildAccel(scene, empty, AccelKind::None);
    brute = traceImage(scene, accel, ro);
  }
  for (uint32_t res : options.resolutions) {
    Grid exact;
    for (OverlapMethod method : options.methods) {
      VoxelizeOptions vo;
      if (res > 0) vo.resolution = res;  // 0: the default heuristic
      vo.method = method;
      VoxelizeStats vs;
      const auto t0 = std::chrono::steady_clock::now();
      Grid grid = voxelizeScene(scene, vo, &vs);
      TradeoffRow row;
      row.voxelizeSeconds = secondsSince(t0);
      row.scene = ts.name;
      row.primitives = scene.primitiveCount();
      row.resolution = res;
      row.dims = grid.dims;
      row.method = methodName(method);
      row.tests = vs.cellsTested;
      row.occupied = grid.occupiedCount();
      row.references = grid.referenceCount();
      if (method == OverlapMethod::Exact) {
        exact = grid;
      } else if (!exact.cellStart.empty() && exact.dims == grid.dims) {
        compareGrids(grid, exact, row);
      }
      if (options.trace) {
        const Accel accel = buildAccel(scene, grid, AccelKind::Grid);
        RenderStats shade, primary;
        const Image image = traceImage(scene, accel, ro, &shade);
        RenderOptions po = ro;
        po.mode = RenderMode::Normals;
        traceImage(scene, accel, po, &primary);
        row.primarySeconds = primary.traceSeconds;
        row.shadeSeconds = shade.traceSeconds;
        const double rays = double(std::max<uint64_t>(1, shade.trace.rays));
        row.cellsPerRay = double(shade.trace.cells) / rays;
        row.testsPerRay = double(shade.trace.tests) / rays;
        row.pixels = uint64_t(image.width) * image.height;
        for (uint64_t p = 0; p < row.pixels; ++p)
          for (uint32_t c = 0; c < image.channels; ++c)
            if (image.pixels[p * image.channels + c] != brute.pixels[p * image.channels + c]) {
              ++row.pixelsDiffering;
              break;
            }
      }
      rows.push_back(row);
    }
  }
  return rows;
}

inline std::string csvHeader() {
  return "scene,primitives,res,nx,ny,nz,method,voxelize_s,tests,tests_per_s,occupied,references,cells_added,"
         "cells_missed,refs_added,refs_missed,primary_s,shade_s,cells_per_ray,tests_per_ray,pixels_differing,pixels";
}

inline std::string csvLine(const TradeoffRow& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "%s,%zu,%u,%u,%u,%u,%s,%.6f,%llu,%.0f,%llu,%llu,%llu,%llu,%llu,%llu,%.6f,%.6f,%.3f,%.3f,%llu,%llu",
                r.scene.c_str(), r.primitives, r.resolution, r.dims[0], r.dims[1], r.dims[2], r.method.c_str(),
                r.voxelizeSeconds, (unsigned long long)r.tests,
                r.voxelizeSeconds > 0 ? double(r.tests) / r.voxelizeSeconds : 0.0, (unsigned long long)r.occupied,
                (unsigned long long)r.references, (unsigned long long)r.cellsAdded, (unsigned long long)r.cellsMissed,
                (unsigned long long)r.refsAdded, (unsigned long long)r.refsMissed, r.primarySeconds, r.shadeSeconds,
                r.cellsPerRay, r.testsPerRay, (unsigned long long)r.pixelsDiffering, (unsigned long long)r.pixels);
  return buf;
}

// Scenes of issue 5. `small` keeps only the cheap ones (test mode).
inline std::vector<TradeoffScene> tradeoffScenes(const std::string& seedDir, bool small) {
  std::vector<TradeoffScene> out;
  const std::string course = seedDir + "/6837/scenes/";
  out.push_back({"sphere", loadScene(course + "scene5_01_sphere.txt")});
  out.push_back({"spheres_overlap", loadScene(course + "scene5_02_spheres.txt")});
  out.push_back({"sphere_triangles", loadScene(course + "scene5_05_sphere_triangles.txt")});
  out.push_back({"bunny_1k", loadScene(course + "scene5_07_bunny_mesh_1k.txt")});
  {
    // Far from the origin: the 1k bunny moved by 1e7 on every axis, its camera with it.
    Scene far = loadScene(course + "scene5_07_bunny_mesh_1k.txt");
    const Vec3 offset{1e7, 1e7, 1e7};
    for (auto& t : far.triangles)
      for (auto& v : t.v) v = v + offset;
    if (far.camera) far.camera->center = far.camera->center + offset;
    out.push_back({"far_origin", std::move(far)});
  }
  {
    // Many small triangles and a few huge ones: 2000 slivers in the unit cube plus 4 triangles spanning it.
    Scene mixed;
    mixed.materials.push_back({});
    uint64_t state = 12345;
    auto rnd = [&] {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      return double(state >> 11) * 0x1.0p-53;
    };
    for (int i = 0; i < (small ? 300 : 2000); ++i) {
      const Vec3 a{rnd(), rnd(), rnd()};
      mixed.triangles.push_back(
          {{a, a + Vec3{0.01 * rnd(), 0.01 * rnd(), 0}, a + Vec3{0, 0.01 * rnd(), 0.01 * rnd()}}});
    }
    mixed.triangles.push_back({{Vec3{0, 0, 0}, Vec3{1, 0, 1}, Vec3{0, 1, 1}}});
    mixed.triangles.push_back({{Vec3{1, 1, 0}, Vec3{1, 0, 1}, Vec3{0, 1, 1}}});
    mixed.triangles.push_back({{Vec3{0, 0.5, 0}, Vec3{1, 0.5, 0}, Vec3{0.5, 0.5, 1}}});
    mixed.triangles.push_back({{Vec3{0, 0, 0.3}, Vec3{1, 1, 0.7}, Vec3{1, 0, 0.5}}});
    out.push_back({"small_and_huge", std::move(mixed)});
  }
  if (!small) {
    out.push_back({"bunny_40k", loadScene(course + "scene5_09_bunny_mesh_40k.txt")});
    out.push_back({"stanford_69k", loadScene(seedDir + "/meshes/derived/stanford_bunny_69k.obj")});
    out.push_back({"sheencloth_115k", loadScene(seedDir + "/meshes/derived/sheencloth_115k.obj")});
  }
  return out;
}

}  // namespace vox::bench
