// The float filter in front of the double ray-triangle test (trace/float_filter.h, issue 12). It may only reject a
// triangle that the double test misses: checked lane by lane against intersectTriangle on rays built to sit on the
// filter's edge (through vertices and along edges of the triangles, grazing their planes, along cell faces), at
// scales from 1e-30 to 1e30 and far from the origin; then whole walks with the filter against walks without it and
// against the brute force, hit for hit and t bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "trace/float_filter.h"
#include "render_util.h"
#include "vox/trace/accel.h"
#include "vox/trace/intersect.h"
#include "vox/trace/traverse.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::voxelizeWith;

// A scene of `count` random triangles in the box [offset, offset + scale]^3, some of them long slivers, some
// sharing vertices and edges (fans), so that rays through shared edges meet two triangles at once.
Scene randomScene(std::mt19937_64& rng, int count, double scale, const Vec3& offset) {
  std::uniform_real_distribution<double> u(0, 1);
  const auto point = [&] { return offset + Vec3{u(rng), u(rng), u(rng)} * scale; };
  Scene scene;
  scene.materials.push_back({});
  for (int i = 0; i < count; ++i) {
    Triangle t{{point(), point(), point()}};
    if (i % 5 == 1) t.v[2] = t.v[0] + (t.v[1] - t.v[0]) * 0.5 + Vec3{0, 0, 1e-9 * scale};                 // a sliver
    if (i % 3 == 2 && i > 0) t.v[0] = scene.triangles.back().v[1], t.v[1] = scene.triangles.back().v[2];  // a fan
    scene.triangles.push_back(t);
  }
  return scene;
}

// Rays aimed at the filter's weak spots of the scene's triangles: at vertices, at points of edges (exact and 1 ulp
// off), grazing the plane, along axis directions and cell faces, from near and far origins; tiny direction components.
// `grazing`, when given, is set for the rays that start in a triangle's plane.
std::vector<Ray> adversarialRays(std::mt19937_64& rng, const Scene& scene, const Grid& grid, int count,
                                 std::vector<bool>* grazing = nullptr) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Ray> rays;
  const Vec3 extent = grid.bounds.hi - grid.bounds.lo;
  const double size = std::max({extent.x, extent.y, extent.z});
  for (int i = 0; i < count; ++i) {
    const Triangle& t = scene.triangles[rng() % scene.triangles.size()];
    Vec3 target;
    switch (i % 6) {
      case 0:
        target = t.v[rng() % 3];
        break;  // a vertex
      case 1:
        target = t.v[0] + (t.v[1] - t.v[0]) * u(rng);
        break;  // an edge
      case 2:
        target = t.v[1] + (t.v[2] - t.v[1]) * u(rng);
        break;   // another edge
      case 3: {  // an edge, 1 ulp off
        const Vec3 p = t.v[2] + (t.v[0] - t.v[2]) * u(rng);
        target = {std::nextafter(p.x, 2 * p.x + 1), p.y, std::nextafter(p.z, -2 * p.z - 1)};
        break;
      }
      default:
        target = t.v[0] + (t.v[1] - t.v[0]) * (u(rng) / 3) + (t.v[2] - t.v[0]) * (u(rng) / 3);  // inside
    }
    Vec3 origin = grid.bounds.lo + Vec3{u(rng), u(rng), u(rng)} * 1.2 * size - Vec3{0.1, 0.1, 0.1} * size;
    if (i % 7 == 0) origin = target + Vec3{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5} * 1e6 * size;  // far away
    if (i % 11 == 0) {  // grazing: from a point in the triangle's plane, towards the target in that plane
      origin = t.v[0] + (t.v[1] - t.v[0]) * (1.5 + u(rng)) + (t.v[2] - t.v[0]) * (u(rng) - 0.5);
    }
    Vec3 d = target - origin;
    if (i % 13 == 0) d.at(int(rng() % 3)) = 1e-30 * size;  // a tiny component
    if (i % 17 == 0) {  // along a cell face: one coordinate of origin and direction on a grid boundary
      const int a = int(rng() % 3);
      origin.at(a) = cellBoundary(grid.bounds, grid.dims, a, int64_t(rng() % (grid.dims[a] + 1)));
      d.at(a) = i % 2 ? 0.0 : -0.0;
    }
    rays.push_back(Ray{origin, d, 0, kInfinity});
    if (grazing) grazing->push_back(i % 11 == 0);
  }
  return rays;
}

// For every ray and every cell's group: no lane the filter rejects is hit by the double test. Returns how many
// (ray, triangle) pairs the double test hit, so that callers can check the rays meant something.
uint64_t expectFilterSound(const Accel& accel, const std::vector<Ray>& rays, uint64_t& rejected,
                           uint64_t& lanesTested) {
  uint64_t hits = 0;
  const FloatCells& fc = accel.floatCells;
  for (size_t r = 0; r < rays.size(); ++r) {
    filter::FilterRay fr;
    if (!filter::prepareFilterRay(fc, rays[r], fr)) continue;
    for (size_t c = 0; c + 1 < fc.cells.size(); ++c)
      for (uint32_t k = 0; k < fc.cells[c].count; k += 4) {
        const TriangleGroup4& g = fc.groups[fc.cells[c].first + k / 4];
        const uint32_t lanes = std::min<uint32_t>(fc.cells[c].count - k, 4);
        const uint32_t maybe = filter::maybeHits(g, fr, lanes);
        for (uint32_t l = 0; l < lanes; ++l) {
          double t = 0;
          const bool hit = intersectTriangle(accel.triangles[g.id[l]], rays[r], t);
          hits += hit;
          ++lanesTested;
          rejected += !(maybe & (1u << l));
          if (hit && !(maybe & (1u << l))) {
            ADD_FAILURE() << "ray " << r << " triangle " << g.id[l] << " rejected but hit";
            return hits;
          }
        }
      }
  }
  return hits;
}

TEST(FloatFilter, NeverRejectsADoubleHit) {
  std::mt19937_64 rng(12);
  const double scales[] = {1e-30, 1e-6, 1, 1e7, 1e30};
  const Vec3 offsets[] = {{0, 0, 0}, {-0.5, -0.5, -0.5}, {1e3, -2e3, 5e2}};
  for (double scale : scales)
    for (const Vec3& off : offsets) {
      const Scene scene = randomScene(rng, 60, scale, off * scale);
      const Grid grid = voxelizeWith(scene, {5, 4, 6});
      const Accel accel = buildAccel(scene, grid, AccelKind::Grid);
      ASSERT_TRUE(accel.floatCells.enabled) << "scale " << scale;
      uint64_t rejected = 0, lanes = 0;
      const uint64_t hits = expectFilterSound(accel, adversarialRays(rng, scene, grid, 400), rejected, lanes);
      EXPECT_GT(hits, 100u) << "scale " << scale;
      EXPECT_GT(rejected, (lanes - hits) * 3 / 4) << "scale " << scale;  // most misses (not those behind the origin)
    }
}

// Far from the origin the scene is a speck: 1e12 units away, triangles 1e-3 across. The scaling about the grid's
// centre keeps the filter exact enough to reject, and sound.
TEST(FloatFilter, FarFromTheOrigin) {
  std::mt19937_64 rng(7);
  const Scene scene = randomScene(rng, 50, 1e-3, Vec3{1e12, -3e12, 7e11});
  const Grid grid = voxelizeWith(scene, {4, 4, 4});
  const Accel accel = buildAccel(scene, grid, AccelKind::Grid);
  ASSERT_TRUE(accel.floatCells.enabled);
  uint64_t rejected = 0, lanes = 0;
  const uint64_t hits = expectFilterSound(accel, adversarialRays(rng, scene, grid, 400), rejected, lanes);
  EXPECT_GT(hits, 100u);
  EXPECT_GT(rejected, (lanes - hits) * 3 / 4);
}

// Whole walks: the filtered walk returns what the walk without it and the brute force return, t bit for bit, for
// nearest hits and occlusion; rays along cell faces and edges, through vertices and edges shared by two triangles.
// Rays that start in a triangle's plane are compared with the walk without the filter only: the double test can
// report such a triangle at a t where its rounding noise (det near 0) puts the point outside the triangle and its
// cells, which no walk visits (the same with and without the filter).
TEST(FloatFilter, WalksEqualDoubleOnlyAndBruteForce) {
  std::mt19937_64 rng(99);
  for (double scale : {1e-6, 1.0, 1e6}) {
    const Scene scene = randomScene(rng, 200, scale, Vec3{3, -1, 2} * scale);
    const Grid grid = voxelizeWith(scene, {9, 7, 8});
    const Accel filtered = buildAccel(scene, grid, AccelKind::Grid);
    Accel doubleOnly = buildAccel(scene, grid, AccelKind::Grid);
    doubleOnly.floatCells = {};
    const Accel brute = buildAccel(scene, grid, AccelKind::None);
    ASSERT_TRUE(filtered.floatCells.enabled);
    TraceStats st;
    int hits = 0;
    std::vector<bool> grazing;
    const std::vector<Ray> rays = adversarialRays(rng, scene, grid, 1500, &grazing);
    for (size_t r = 0; r < rays.size(); ++r) {
      Ray ray = rays[r];
      for (double tMax : {kInfinity, 0.5}) {
        ray.tMax = tMax;
        const Hit a = traceRay(filtered, ray, &st), b = traceRay(doubleOnly, ray), c = traceRay(brute, ray);
        ASSERT_EQ(a.prim, b.prim);
        ASSERT_EQ(0, std::memcmp(&a.t, &b.t, sizeof(double)));
        ASSERT_EQ(occluded(filtered, ray), occluded(doubleOnly, ray));
        hits += a.valid();
        if (grazing[r]) continue;
        ASSERT_EQ(a.prim, c.prim) << "o=(" << ray.origin.x << "," << ray.origin.y << "," << ray.origin.z << ") d=("
                                  << ray.direction.x << "," << ray.direction.y << "," << ray.direction.z << ") t "
                                  << a.t << " " << c.t << " tMax " << tMax;
        ASSERT_EQ(0, std::memcmp(&a.t, &c.t, sizeof(double)));
        ASSERT_EQ(occluded(filtered, ray), occluded(brute, ray));
      }
    }
    EXPECT_GT(hits, 500) << "scale " << scale;
    EXPECT_GT(st.filtered, st.tests) << "scale " << scale;
  }
}

// A grid whose vertices cannot be scaled into the filter's range leaves it off, and walks still work.
TEST(FloatFilter, OffOutsideItsRange) {
  Scene scene;
  scene.materials.push_back({});
  scene.triangles.push_back(Triangle{{Vec3{0, 0, 0}, Vec3{1e-80, 0, 0}, Vec3{0, 1e-80, 0}}});
  const Grid grid = voxelizeWith(scene, {2, 2, 1});
  const Accel accel = buildAccel(scene, grid, AccelKind::Grid);
  EXPECT_FALSE(accel.floatCells.enabled);
  const Hit h = traceRay(accel, Ray{{2e-81, 2e-81, 1}, {0, 0, -1}, 0, kInfinity});
  EXPECT_EQ(h.prim, 0u);
  filter::FilterRay fr;
  EXPECT_FALSE(filter::prepareFilterRay(accel.floatCells, Ray{}, fr));
}

}  // namespace
}  // namespace vox
