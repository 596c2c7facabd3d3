// Voxel meshes (voxel_mesh.h). Pure geometry: no file I/O here. This file: the voxels of a grid and their colours,
// the face modes (the exposed surface in exposed_surface.cpp, its merged form in merged_mesh.cpp) and the
// triangulation that the triangle-only formats need.
#include "vox/export/voxel_mesh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <mutex>

#include "vox/export/cell_color.h"
#include "vox/core/colormap.h"
#include "export/export_budget.h"
#include "export/voxel_surface.h"
#include "vox/core/checked_math.h"
#include "vox/core/error.h"
#include "vox/export/voxel_runs.h"

namespace vox {

using namespace voxel_surface;

FaceMode parseFaceMode(const std::string& name) {
  for (auto m : {FaceMode::All, FaceMode::Exposed, FaceMode::Merged})
    if (faceModeName(m) == name) return m;
  fail<InputError>("unknown face mode '", name, "' (expected all, exposed or merged)");
}

ColorMode parseColorMode(const std::string& name) {
  for (auto m : {ColorMode::Count, ColorMode::Material, ColorMode::None})
    if (colorModeName(m) == name) return m;
  fail<InputError>("unknown colour mode '", name, "' (expected count, material or none)");
}

std::string faceModeName(FaceMode mode) {
  switch (mode) {
    case FaceMode::All:
      return "all";
    case FaceMode::Exposed:
      return "exposed";
    case FaceMode::Merged:
      return "merged";
  }
  return "unknown";
}

std::string colorModeName(ColorMode mode) {
  switch (mode) {
    case ColorMode::Count:
      return "count";
    case ColorMode::Material:
      return "material";
    case ColorMode::None:
      return "none";
  }
  return "unknown";
}

namespace {

uint8_t toByte(double x) { return uint8_t(std::lround(std::clamp(std::isfinite(x) ? x : 0.0, 0.0, 1.0) * 255.0)); }
Rgb8 toRgb8(const Vec3& c) { return {toByte(c.x), toByte(c.y), toByte(c.z)}; }

// ---------------------------------------------------------------------------------------------------------------
// Voxels and their colours.

uint32_t majorityMaterialColor(const Grid& grid, const Scene& scene, size_t cell) {
  return packColor(toRgb8(cellMaterialColor(grid, scene, cell)));  // image textures included (cell_color.h)
}

// The packed colour of each occupied cell (kNoColor for ColorMode::None); shared by the meshes and by
// occupiedCellColors (the voxel formats), so a cell has one colour in every export. Count reads only cellStart,
// against maxCount (0: the grid's own largest count). Reports to `progress` over its current phase.
std::vector<uint32_t> occupiedColors(const Grid& grid, const Scene& scene, ColorMode mode, uint32_t maxCount,
                                     ExportProgress& progress) {
  const size_t nOcc = grid.cellKeys.size();
  if (grid.cellStart.size() != nOcc + 1 || (mode != ColorMode::Count && grid.cellStart.back() > grid.primIds.size()))
    fail<InputError>("grid: inconsistent cell table (", nOcc, " cells, ", grid.cellStart.size(), " offsets)");
  static_assert(kNoColor == 0);  // what resize gives
  std::vector<uint32_t> occColor;
  progress.resize(occColor, nOcc);
  if (mode == ColorMode::Count) {
    if (maxCount == 0) maxCount = largestCellCount(grid);
    progress.parallelFor(nOcc, [&](const tbb::blocked_range<size_t>& r) {
      for (size_t c = r.begin(); c != r.end(); ++c)
        occColor[c] = packColor(toRgb8(countColor(uint32_t(grid.cellStart[c + 1] - grid.cellStart[c]), maxCount)));
    });
  } else if (mode == ColorMode::Material) {
    std::mutex errorMutex;
    std::exception_ptr error;
    const auto paint = [&](const tbb::blocked_range<size_t>& r) {
      try {
        for (size_t c = r.begin(); c != r.end(); ++c) occColor[c] = majorityMaterialColor(grid, scene, c);
      } catch (...) {
        std::lock_guard lock(errorMutex);
        if (!error) error = std::current_exception();
      }
    };
    try {
      progress.parallelFor(nOcc, paint);
    } catch (const Error&) {
      if (!error) throw;  // cancelled; a bad cell found meanwhile is the better message
    }
    if (error) std::rethrow_exception(error);
  }
  return occColor;
}

// Bytes per voxel at the peak of each face mode, for the estimate made before the voxel list exists. Exposed and
// Merged: the voxel list (key 8, colour 4) alive while buildBricks holds its entries (brick key 8, local index 4,
// colour 4) and the bricks' colours (4); what follows is per brick, vertex or square and checked where it is
// allocated. All: the voxel list and the cubes (8 positions of 24 bytes, 36 vertex ids and 12 face starts of 4, 12
// colours of 3).
constexpr uint64_t kSurfaceBytesPerVoxel = 12 + 16 + 4;
constexpr uint64_t kCubeBytesPerVoxel = 12 + 8 * sizeof(Vec3) + 36 * 4 + 12 * 4 + 12 * 3;

// The voxels and their colours: the colours are [0, 0.8] of `progress`'s range, the merge the rest.
Voxels gatherVoxels(const Grid& grid, const Scene& scene, ColorMode mode, uint64_t bytesPerVoxel,
                    ExportProgress& progress) {
  const size_t nOcc = grid.cellKeys.size();
  if (grid.cellStart.size() != nOcc + 1 || grid.cellStart.back() > grid.primIds.size())
    fail<InputError>("grid: inconsistent cell table (", nOcc, " cells, ", grid.cellStart.size(), " offsets)");
  // Counted from the keys and runs (which this checks) without expanding them, so that a grid of 2^63 solid cells
  // is refused at once instead of after its list has grown to the memory's end.
  const uint64_t voxels = tallyVoxels(grid).voxels;
  requireMemory(saturatingMul(voxels, bytesPerVoxel), "voxel mesh",
                "a list of " + describeCount(voxels) + " voxels at " + std::to_string(bytesPerVoxel) + " bytes each");

  const std::vector<uint32_t> occColor = [&] {
    progress.phase(0, 0.8);
    return occupiedColors(grid, scene, mode, 0, progress);
  }();
  progress.phase(0.8, 1);

  // Merge occupied keys and solid runs; a cell in both is drawn once, with its occupied colour.
  const uint32_t solid = mode == ColorMode::None ? kNoColor : packColor(kSolidCellColor);
  Voxels v;
  v.keys.reserve(voxels);
  v.colors.reserve(voxels);
  size_t a = 0;
  for (const CellRun& run : grid.solidRuns) {
    for (uint64_t key = run.first; key < run.first + run.count; ++key) {
      for (; a < nOcc && grid.cellKeys[a] < key; ++a) {
        v.keys.push_back(grid.cellKeys[a]);
        v.colors.push_back(occColor[a]);
      }
      progress.step(v.keys.size(), voxels);
      if (a < nOcc && grid.cellKeys[a] == key) continue;  // occupied wins; pushed by the loop above next time
      v.keys.push_back(key);
      v.colors.push_back(solid);
    }
  }
  for (; a < nOcc; ++a) {
    progress.step(a, nOcc);
    v.keys.push_back(grid.cellKeys[a]);
    v.colors.push_back(occColor[a]);
  }
  return v;
}

// ---------------------------------------------------------------------------------------------------------------
// FaceMode::All

VoxelMesh buildCubes(const Voxels& vox, const Lattice& lat, bool colored, ExportProgress& progress) {
  const size_t n = vox.keys.size();
  checkVertexCount(uint64_t(n) * 8);
  VoxelMesh mesh;
  progress.resize(mesh.positions, n * 8);
  progress.resize(mesh.faceVertices, n * 36);
  progress.resize(mesh.faceStart, n * 12 + 1);
  if (colored) progress.resize(mesh.faceColors, n * 12);
  // Corner c of the cube is (c&1, c>>1&1, c>>2&1); the triangles are counter-clockwise seen from outside.
  static constexpr uint8_t kTris[12][3] = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5},   // -x, +x
                                           {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},   // -y, +y
                                           {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};  // -z, +z
  progress.parallelFor(n, [&](const tbb::blocked_range<size_t>& r) {
    for (size_t v = r.begin(); v != r.end(); ++v) {
      const auto ijk = cellIndex(lat.dims, vox.keys[v]);
      for (uint32_t c = 0; c < 8; ++c)
        mesh.positions[v * 8 + c] = lat.point(ijk[0] + (c & 1), ijk[1] + ((c >> 1) & 1), ijk[2] + ((c >> 2) & 1));
      for (size_t t = 0; t < 12; ++t) {
        for (int k = 0; k < 3; ++k) mesh.faceVertices[v * 36 + t * 3 + k] = uint32_t(v * 8 + kTris[t][k]);
        mesh.faceStart[v * 12 + t + 1] = uint32_t(v * 36 + t * 3 + 3);
        if (colored) mesh.faceColors[v * 12 + t] = unpackColor(vox.colors[v]);
      }
    }
  });
  return mesh;
}

}  // namespace

VoxelMesh buildVoxelMesh(const Grid& grid, const Scene& scene, FaceMode faces, ColorMode color, VoxelMeshStats* stats,
                         const std::function<bool(double)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  ExportProgress report(progress, "voxel mesh");
  // The shares of the phases: about their times for the bunny at 512^3 with colours.
  report.within(0, 0.25);
  const Voxels vox =
      gatherVoxels(grid, scene, color, faces == FaceMode::All ? kCubeBytesPerVoxel : kSurfaceBytesPerVoxel, report);
  const Lattice lat{grid.bounds, grid.dims};
  const bool colored = color != ColorMode::None;
  VoxelMesh mesh;
  size_t exposed = 0;
  if (faces == FaceMode::All) {
    report.within(0.25, 1);
    mesh = buildCubes(vox, lat, colored, report);
  } else {
    report.within(0.25, 0.7);
    ExposedSurface surface = buildExposed(vox, lat, report);
    exposed = surface.squares.size();
    report.within(0.7, 1);
    mesh = faces == FaceMode::Exposed ? exposedMesh(std::move(surface), colored, report)
                                      : mergedMesh(std::move(surface), grid.dims, colored, report);
  }
  report.check();
  if (stats) {
    stats->voxels = vox.keys.size();
    stats->exposedFaces = exposed;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return mesh;
}

// ---------------------------------------------------------------------------------------------------------------
// Triangulation.

namespace {

// The axis along which p and q differ (they lie on an axis-parallel line), or -1 if they differ along several.
int segmentAxis(const Vec3& p, const Vec3& q) {
  int axis = -1;
  for (int a = 0; a < 3; ++a)
    if (p[a] != q[a]) {
      if (axis >= 0) return -1;
      axis = a;
    }
  return axis;
}

}  // namespace

std::vector<Rgb8> dominantVertexColors(const VoxelMesh& mesh) {
  if (!mesh.hasColors()) return {};
  const size_t nv = mesh.vertexCount(), nf = mesh.faceCount();
  // Corners grouped by vertex (counting sort), then a small tally per vertex: voxel meshes have a handful of
  // corners per vertex.
  std::vector<uint32_t> cornerStart(nv + 1, 0);
  for (uint32_t v : mesh.faceVertices) ++cornerStart[v + 1];
  for (size_t v = 0; v < nv; ++v) cornerStart[v + 1] += cornerStart[v];
  struct Corner {
    uint32_t color;
    double angle;
  };
  std::vector<Corner> corners(mesh.faceVertices.size());
  {
    std::vector<uint32_t> cursor(cornerStart.begin(), cornerStart.end() - 1);
    for (size_t f = 0; f < nf; ++f) {
      const uint32_t b = mesh.faceStart[f], e = mesh.faceStart[f + 1], n = e - b;
      const uint32_t color = packColor(mesh.faceColors[f]);
      for (uint32_t k = 0; k < n; ++k) {
        const uint32_t u = mesh.faceVertices[b + (k + n - 1) % n], v = mesh.faceVertices[b + k],
                       w = mesh.faceVertices[b + (k + 1) % n];
        const Vec3 a = mesh.positions[u] - mesh.positions[v], c = mesh.positions[w] - mesh.positions[v];
        corners[cursor[v]++] = {color, std::atan2(length(cross(a, c)), dot(a, c))};
      }
    }
  }
  std::vector<Rgb8> colors(nv, Rgb8{255, 255, 255});
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<std::pair<uint32_t, double>> tally;
    for (size_t v = r.begin(); v != r.end(); ++v) {
      tally.clear();
      for (uint32_t k = cornerStart[v]; k < cornerStart[v + 1]; ++k) {
        auto it = std::find_if(tally.begin(), tally.end(), [&](const auto& t) { return t.first == corners[k].color; });
        if (it == tally.end())
          tally.push_back({corners[k].color, corners[k].angle});
        else
          it->second += corners[k].angle;
      }
      if (tally.empty()) continue;
      // Packed as 0x01BBGGRR; compare as (r, g, b) for the documented tie rule.
      auto rgbKey = [](uint32_t c) { return ((c & 0xFF) << 16) | (c & 0xFF00) | ((c >> 16) & 0xFF); };
      auto best = tally.front();
      for (const auto& t : tally)
        if (t.second > best.second || (t.second == best.second && rgbKey(t.first) < rgbKey(best.first))) best = t;
      colors[v] = unpackColor(best.first);
    }
  });
  return colors;
}

VoxelMesh triangulateVoxelMesh(const VoxelMesh& mesh, const std::function<bool(double)>& progress) {
  ExportProgress report(progress, "triangulation");
  const size_t nf = mesh.faceCount();
  std::vector<size_t> triStart;
  report.phase(0, 0.1);
  report.resize(triStart, nf + 1);
  for (size_t f = 0; f < nf; ++f) {
    report.step(f, nf);
    triStart[f + 1] = triStart[f] + (mesh.faceSize(f) >= 3 ? mesh.faceSize(f) - 2 : 0);
  }
  report.phase(0.1, 1);
  VoxelMesh out;
  report.resize(out.positions, mesh.positions.size());
  report.resize(out.faceVertices, 3 * triStart[nf]);
  report.resize(out.faceStart, triStart[nf] + 1);
  if (mesh.hasColors()) report.resize(out.faceColors, triStart[nf]);
  report.parallelFor(mesh.positions.size(), [&](const tbb::blocked_range<size_t>& r) {
    std::copy(mesh.positions.begin() + ptrdiff_t(r.begin()), mesh.positions.begin() + ptrdiff_t(r.end()),
              out.positions.begin() + ptrdiff_t(r.begin()));
  });
  report.parallelFor(nf, [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> poly, tris;
    for (size_t f = r.begin(); f != r.end(); ++f) {
      poly.assign(mesh.faceVertices.begin() + mesh.faceStart[f], mesh.faceVertices.begin() + mesh.faceStart[f + 1]);
      const size_t n = poly.size();
      tris.clear();
      std::array<size_t, 4> corner{};
      int corners = 0;
      bool rect = n >= 4;
      for (size_t k = 0; k < n && rect; ++k) {
        const int in = segmentAxis(mesh.positions[poly[(k + n - 1) % n]], mesh.positions[poly[k]]);
        const int outAxis = segmentAxis(mesh.positions[poly[k]], mesh.positions[poly[(k + 1) % n]]);
        if (in < 0 || outAxis < 0)
          rect = false;
        else if (in != outAxis) {
          if (corners == 4)
            rect = false;
          else
            corner[corners++] = k;
        }
      }
      if (rect && corners == 4) {
        triangulateRectangle(poly, mesh.positions, corner, tris);
      } else {
        for (size_t k = 1; k + 1 < n; ++k) tris.insert(tris.end(), {poly[0], poly[k], poly[k + 1]});
      }
      VOX_CHECK(tris.size() == 3 * (triStart[f + 1] - triStart[f]));
      std::copy(tris.begin(), tris.end(), out.faceVertices.begin() + ptrdiff_t(3 * triStart[f]));
      for (size_t t = triStart[f]; t < triStart[f + 1]; ++t) {
        out.faceStart[t + 1] = uint32_t(3 * (t + 1));
        if (mesh.hasColors()) out.faceColors[t] = mesh.faceColors[f];
      }
    }
  });
  return out;
}

uint32_t largestCellCount(const Grid& grid) {
  uint32_t n = 0;
  for (size_t c = 0; c + 1 < grid.cellStart.size(); ++c)
    n = std::max<uint32_t>(n, uint32_t(grid.cellStart[c + 1] - grid.cellStart[c]));
  return n;
}

std::vector<Rgb8> occupiedCellColors(const Grid& grid, const Scene& scene, ColorMode color, uint32_t maxCount,
                                     const std::function<bool(double)>& progress) {
  if (color == ColorMode::None) return {};
  ExportProgress report(progress, "cell colours");
  report.within(0, 0.9);
  const std::vector<uint32_t> packed = occupiedColors(grid, scene, color, maxCount, report);
  report.within(0.9, 1);
  std::vector<Rgb8> colors(packed.size());
  for (size_t c = 0; c < packed.size(); ++c) {
    report.step(c, packed.size());
    colors[c] = unpackColor(packed[c]);
  }
  return colors;
}

}  // namespace vox
