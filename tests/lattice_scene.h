// Test scenes whose cell boundaries are integers, so that rays exactly along cell faces, edges and through corners,
// and triangles one ulp from a face, can be written down exactly; shared by the walker and packet tests.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "vox/core/grid.h"
#include "vox/trace/ray.h"
#include "vox/core/scene.h"
#include "vox/voxelize/voxelize.h"

namespace vox::testing {

// A lattice of small triangles, one around the centre of many cells, in [0, n]^3 with n^3 unit cells, plus
// triangles lying exactly in cell faces.
inline Scene latticeScene(int n, double scale = 1, Vec3 offset = {}) {
  Scene scene;
  scene.materials.push_back({});
  std::mt19937 rng(n);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if ((i + 2 * j + 3 * k) % 4 != 0) continue;
        const Vec3 c{i + u(rng), j + u(rng), k + u(rng)};
        Triangle t{{c + Vec3{-0.3, -0.3, 0.1}, c + Vec3{0.3, -0.2, -0.1}, c + Vec3{0, 0.3, 0}}};
        for (auto& v : t.v) v = offset + v * scale;
        scene.triangles.push_back(t);
      }
  // Triangles in the faces x = 1, y = 2 and z = n - 1 (cell boundaries).
  const double f = n - 1;
  Triangle a{{Vec3{1, 0.5, 0.5}, Vec3{1, f, 0.5}, Vec3{1, 0.5, f}}};
  Triangle b{{Vec3{0.5, 2, 0.5}, Vec3{f, 2, 0.5}, Vec3{0.5, 2, f}}};
  Triangle c{{Vec3{0.5, 0.5, f}, Vec3{f, 0.5, f}, Vec3{0.5, f, f}}};
  for (Triangle t : {a, b, c}) {
    for (auto& v : t.v) v = offset + v * scale;
    scene.triangles.push_back(t);
  }
  return scene;
}

inline Grid latticeGrid(const Scene& scene, int n, double scale = 1, Vec3 offset = {}) {
  const Box bounds{offset, offset + Vec3{double(n), double(n), double(n)} * scale};
  VoxelizeOptions o;
  o.dims = {uint32_t(n), uint32_t(n), uint32_t(n)};
  o.bounds = bounds;
  return voxelizeScene(scene, o);
}

// Rays exactly along cell faces and edges, axis-parallel, with +-0 and -0.0 components and 1e-30 components.
inline std::vector<Ray> specialRays(int n, double scale = 1, Vec3 offset = {}) {
  std::vector<Ray> rays;
  auto add = [&](Vec3 o, Vec3 d) { rays.push_back(Ray{offset + o * scale, d}); };
  const double far = n + 5;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; j += 1) {
      // Along z, exactly on the edge x = i, y = j; in both directions; with -0.0 and 1e-30 components.
      add({double(i), double(j), far}, {0, 0, -1});
      add({double(i), double(j), -5}, {-0.0, -0.0, 1});
      add({double(i), double(j), far}, {1e-30, -1e-30, -1});
      add({double(i), double(j), far}, {-1e-30, -0.0, -1});
      // Along x in the face y = j (z inside a cell), along y in the face z = i.
      add({-5, double(j), i + 0.37}, {1, -0.0, 0});
      add({far, i + 0.61, double(j)}, {-1, 0, 1e-30});
    }
    // Through the corners (k, k, k) and through edges of the diagonal.
    add({-1, -1, -1}, {1, 1, 1});
    add({far, far, far}, {-1, -1, -1});
    add({double(i), -1, -1}, {0, 1, 1});
    add({-1, double(i), 0.5}, {1, 1, 0});
  }
  return rays;
}

// Triangle A covers the square [0, 4]^2 of the cell face x = 2 (ids 2 and 3, in the cells on both sides), triangle B
// the same square one ulp beyond it in the direction of travel (ids 0 and 1, in one cell only); a fifth triangle
// pins the bounds to [0, 4]^3. Voxelized exactly into 4x4x4 cells. Rays aimed at the plane from far away see A and B
// at equal t or an ulp apart, so the nearest hit (ties to the smaller id) is often B, which only the cells after A's
// reveal: a walk that stops as soon as a hit lies within the current cell misses it.
struct NearCoincidentPlanes {
  Scene scene;
  Grid grid;
};
inline NearCoincidentPlanes nearCoincidentPlanes(bool forward) {
  NearCoincidentPlanes c;
  c.scene.materials.push_back({});
  const auto square = [&](double x) {
    c.scene.triangles.push_back(Triangle{{Vec3{x, 0, 0}, Vec3{x, 4, 0}, Vec3{x, 4, 4}}});
    c.scene.triangles.push_back(Triangle{{Vec3{x, 0, 0}, Vec3{x, 4, 4}, Vec3{x, 0, 4}}});
  };
  square(forward ? std::nextafter(2.0, 3.0) : std::nextafter(2.0, 1.0));  // B
  square(2.0);                                                            // A
  c.scene.triangles.push_back(Triangle{{Vec3{0, 0, 0}, Vec3{4, 0, 0}, Vec3{0, 4, 4}}});
  VoxelizeOptions o;
  o.dims = {4, 4, 4};
  o.bounds = Box{{0, 0, 0}, {4, 4, 4}};
  c.grid = voxelizeScene(c.scene, o);
  return c;
}
// Rays towards random points of the plane x = 2, from 1000 direction lengths away (so that t is large and its ulp
// dwarfs the one-ulp gap between the planes), travelling in +x when `forward`, nearly along x.
inline std::vector<Ray> raysAtNearCoincidentPlanes(std::mt19937& rng, bool forward, int count) {
  std::uniform_real_distribution<double> u(0.2, 3.8), dir(-0.001, 0.001);
  std::vector<Ray> rays;
  for (int r = 0; r < count; ++r) {
    const Vec3 target{2, u(rng), u(rng)};
    const double dx = 0.5 + (u(rng) - 0.2) / 3.6;
    const Vec3 d{forward ? dx : -dx, dir(rng), dir(rng)};
    rays.push_back(Ray{target - d * 1000.0, d});
  }
  return rays;
}

}  // namespace vox::testing
