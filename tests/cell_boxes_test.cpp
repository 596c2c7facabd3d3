// Accel::cellBoxes (issue 27): every box holds no occupied cell, no box can grow by a layer, and the walk that
// jumps over them finds the brute-force hit bit for bit, with fewer cells visited than the uniform walk.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "render_util.h"
#include "vox/trace/accel.h"
#include "vox/trace/traverse.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

using testing::voxelizeWith;

// A few small triangles scattered in the unit cube: wide empty spaces between them.
Scene scatteredTriangles(std::mt19937& rng, int count, double scale, const Vec3& offset) {
  std::uniform_real_distribution<double> u(0, 1), small(-0.05, 0.05);
  Scene scene;
  scene.materials.push_back(Material{"m"});
  for (int t = 0; t < count; ++t) {
    const Vec3 c{u(rng), u(rng), u(rng)};
    Triangle tri;
    for (auto& v : tri.v) v = (c + Vec3{small(rng), small(rng), small(rng)}) * scale + offset;
    tri.material = 0;
    scene.triangles.push_back(tri);
  }
  return scene;
}

bool occupied(const Accel& a, uint32_t i, uint32_t j, uint32_t k) {
  return !a.blockEmpty(i, j, k) && a.lookup(i, j, k) < kSolidCell;
}

// Valid (no occupied cell inside) and maximal (each face at the grid's edge, at the reach cap, or against a layer
// holding an occupied cell): a box shrunk by one cell or grown over an occupied one fails.
void expectBoxesValidAndMaximal(const Accel& a, uint64_t& checked) {
  const auto& d = a.grid->dims;
  ASSERT_FALSE(a.cellBoxes.empty());
  for (uint32_t k = 0; k < d[2]; ++k)
    for (uint32_t j = 0; j < d[1]; ++j)
      for (uint32_t i = 0; i < d[0]; ++i) {
        const uint64_t slot = a.slotOf(i, j, k);
        if (slot == UINT64_MAX || occupied(a, i, j, k)) continue;
        const CellBox& b = a.cellBoxes[slot];
        const std::array<int64_t, 3> c{i, j, k};
        std::array<int64_t, 3> lo, hi;
        for (int ax = 0; ax < 3; ++ax) {
          lo[ax] = c[ax] - b.lo[ax];
          hi[ax] = c[ax] + b.hi[ax];
          ASSERT_GE(lo[ax], 0);
          ASSERT_LT(hi[ax], int64_t(d[ax]));
        }
        const auto anyOccupied = [&](std::array<int64_t, 3> l, std::array<int64_t, 3> h) {
          for (int64_t z = l[2]; z <= h[2]; ++z)
            for (int64_t y = l[1]; y <= h[1]; ++y)
              for (int64_t x = l[0]; x <= h[0]; ++x)
                if (occupied(a, uint32_t(x), uint32_t(y), uint32_t(z))) return true;
          return false;
        };
        ASSERT_FALSE(anyOccupied(lo, hi)) << "box of cell " << i << "," << j << "," << k << " holds an occupied cell";
        for (int face = 0; face < 6; ++face) {
          const int ax = face / 2;
          const bool up = face % 2 == 1;
          const int64_t reach = up ? b.hi[ax] : b.lo[ax];
          const int64_t layer = up ? hi[ax] + 1 : lo[ax] - 1;
          if (layer < 0 || layer >= int64_t(d[ax]) || reach >= 16) continue;
          std::array<int64_t, 3> l = lo, h = hi;
          l[ax] = h[ax] = layer;
          ASSERT_TRUE(anyOccupied(l, h)) << "box of cell " << i << "," << j << "," << k << " could grow on face "
                                         << face;
        }
        ++checked;
      }
}

TEST(CellBoxes, ValidAndMaximalOnScatteredScenes) {
  std::mt19937 rng(27);
  uint64_t checked = 0;
  for (const std::array<uint32_t, 3> dims : {std::array<uint32_t, 3>{1, 1, 1}, {7, 5, 3}, {24, 24, 24}, {40, 3, 17}}) {
    const Scene scene = scatteredTriangles(rng, 6, 1, {0, 0, 0});
    const Grid grid = voxelizeWith(scene, dims);
    const Accel a = buildAccel(scene, grid, AccelKind::Grid);
    if (a.blockShift == 0) continue;
    expectBoxesValidAndMaximal(a, checked);
    EXPECT_TRUE(buildAccel(scene, grid, AccelKind::Uniform).cellBoxes.empty());
  }
  EXPECT_GT(checked, 1000u);
}

// Rays from lattice points (cell corners, edges, faces) and random points, along axes, face diagonals and random
// directions, at scales from 1e-30 to 1e30 and 1e12 from the origin: the jumping walk, the uniform walk and brute
// force agree bit for bit.
TEST(CellBoxes, JumpingWalkEqualsBruteForceAtEveryScale) {
  std::mt19937 rng(2027);
  uint64_t jumpCells = 0, uniformCells = 0;
  int hits = 0;
  for (const double scale : {1e-30, 1e-6, 1.0, 1e6, 1e30})
    for (const double offset : {0.0, 1e12}) {
      const Vec3 off{offset * (scale >= 1 ? scale : 1), -offset, offset};
      const Scene scene = scatteredTriangles(rng, 8, scale, off);
      const std::array<uint32_t, 3> dims{20, 17, 23};
      const Grid grid = voxelizeWith(scene, dims);
      const Accel jump = buildAccel(scene, grid, AccelKind::Grid);
      const Accel uniform = buildAccel(scene, grid, AccelKind::Uniform);
      const Accel brute = buildAccel(scene, grid, AccelKind::None);
      const Box& b = grid.bounds;
      std::uniform_int_distribution<int> lattice(0, 23);
      std::uniform_real_distribution<double> u(-0.2, 1.2);
      std::normal_distribution<double> n(0, 1);
      for (int r = 0; r < 3000; ++r) {
        Ray ray;
        for (int a = 0; a < 3; ++a) {
          const double f = r % 2 ? double(std::min<int>(lattice(rng), int(dims[a]))) / dims[a] : u(rng);
          ray.origin.at(a) = b.lo[a] + (b.hi[a] - b.lo[a]) * f;
        }
        switch (r % 5) {
          case 0:  // along an axis
            ray.direction = Vec3{0, 0, 0};
            ray.direction.at(r / 5 % 3) = (r / 15) % 2 ? 1 : -1;
            break;
          case 1:  // a face diagonal, through edges
            ray.direction = Vec3{1, (r / 5) % 2 ? 1.0 : -1.0, 0};
            break;
          case 2:  // at a triangle's corner, so that many rays hit
            ray.direction = scene.triangles[size_t(r) % scene.triangles.size()].v[size_t(r) % 3] - ray.origin;
            break;
          default:
            ray.direction = Vec3{n(rng), n(rng), n(rng)};
        }
        TraceStats sj, su;
        const Hit hj = traceRay(jump, ray, &sj), hu = traceRay(uniform, ray, &su), hb = traceRay(brute, ray);
        ASSERT_EQ(hj.prim, hb.prim) << "scale " << scale << " offset " << offset << " ray " << r;
        ASSERT_EQ(hj.t, hb.t) << "scale " << scale << " offset " << offset << " ray " << r;
        ASSERT_EQ(hu.prim, hb.prim);
        ASSERT_EQ(occluded(jump, ray), occluded(brute, ray)) << "scale " << scale << " ray " << r;
        jumpCells += sj.cells;
        uniformCells += su.cells;
        hits += hb.valid();
      }
    }
  EXPECT_GT(hits, 2000);
  EXPECT_LT(jumpCells, uniformCells) << "the boxes never saved a cell";
}

}  // namespace
}  // namespace vox
