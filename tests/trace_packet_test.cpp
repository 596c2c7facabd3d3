// tracePacket must return, for every ray, exactly what traceRay returns (and so what the brute force returns on
// exact, sat and bbox grids): same primitive, same t bit for bit; occludedPacket what occluded returns. Coherent
// packets take the slice walk; the tests check that they do (fewer cells than the rays' own walks), so a silent
// fallback to single rays cannot pass them.
#include <gtest/gtest.h>

#include <bit>
#include <memory>
#include <random>
#include <sstream>

#include "lattice_scene.h"
#include "test_util.h"
#include "vox/trace/accel.h"
#include "vox/core/error.h"
#include "vox/trace/render.h"
#include "vox/trace/trace_packet.h"
#include "vox/voxelize/voxelize.h"

namespace vox {
namespace {

std::string describe(const Ray& r) {
  std::ostringstream s;
  s.precision(17);
  s << "o=(" << r.origin.x << "," << r.origin.y << "," << r.origin.z << ") d=(" << r.direction.x << "," << r.direction.y
    << "," << r.direction.z << ") t=[" << r.tMin << "," << r.tMax << "]";
  return s.str();
}

struct PacketCheck {
  uint64_t packetCells = 0, rayCells = 0, hits = 0;
};

// Traces `rays` in packets of `packetSize` and one by one, with the grid and by brute force, and compares.
PacketCheck expectPacketsMatch(const Accel& grid, const Accel& none, const std::vector<Ray>& rays, uint32_t packetSize,
                               const std::string& what) {
  PacketCheck check;
  std::vector<Hit> hits(rays.size());
  TraceStats packetStats, rayStats;
  for (size_t begin = 0; begin < rays.size(); begin += packetSize) {
    const size_t count = std::min<size_t>(packetSize, rays.size() - begin);
    tracePacket(grid, std::span(rays).subspan(begin, count), std::span(hits).subspan(begin, count), &packetStats);
  }
  std::unique_ptr<bool[]> blocked(new bool[rays.size()]);
  for (size_t begin = 0; begin < rays.size(); begin += packetSize) {
    const size_t count = std::min<size_t>(packetSize, rays.size() - begin);
    occludedPacket(grid, std::span(rays).subspan(begin, count), std::span(blocked.get() + begin, count));
  }
  int failures = 0;
  for (size_t r = 0; r < rays.size() && failures < 5; ++r) {
    const bool single = occluded(grid, rays[r]), brute = occluded(none, rays[r]);
    EXPECT_EQ(blocked[r], single) << what << " ray " << r << " " << describe(rays[r]) << ": occlusion";
    EXPECT_EQ(single, brute) << what << " ray " << r << " " << describe(rays[r]) << ": occlusion, brute force";
    failures += blocked[r] != single || single != brute;
  }
  for (size_t r = 0; r < rays.size() && failures < 5; ++r) {
    const Hit single = traceRay(grid, rays[r], &rayStats);
    const Hit brute = traceRay(none, rays[r]);
    const bool same =
        hits[r].prim == single.prim && std::bit_cast<uint64_t>(hits[r].t) == std::bit_cast<uint64_t>(single.t);
    const bool sameBrute =
        single.prim == brute.prim && std::bit_cast<uint64_t>(single.t) == std::bit_cast<uint64_t>(brute.t);
    EXPECT_TRUE(same) << what << " ray " << r << " " << describe(rays[r]) << ": packet prim " << hits[r].prim << " t "
                      << hits[r].t << ", single prim " << single.prim << " t " << single.t;
    EXPECT_TRUE(sameBrute) << what << " ray " << r << " " << describe(rays[r]) << ": single differs from brute force";
    failures += !same || !sameBrute;
    check.hits += single.valid();
  }
  EXPECT_EQ(packetStats.rays, rays.size()) << what;
  check.packetCells = packetStats.cells;
  check.rayCells = rayStats.cells;
  return check;
}

// The primary rays of `camera` in square tiles of tile x tile pixels, tile by tile.
std::vector<Ray> tiledPrimaryRays(const Camera& camera, uint32_t size, uint32_t tile) {
  std::vector<Ray> rays;
  for (uint32_t ty = 0; ty < size; ty += tile)
    for (uint32_t tx = 0; tx < size; tx += tile)
      for (uint32_t y = ty; y < std::min(ty + tile, size); ++y)
        for (uint32_t x = tx; x < std::min(tx + tile, size); ++x)
          rays.push_back(primaryRay(camera, size, size, x + 0.5, y + 0.5));
  return rays;
}

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  return normalize(Vec3{n(rng), n(rng), n(rng)});
}

TEST(TracePacket, RandomScenesAndCamerasMatchSingleRaysAndBruteForce) {
  for (uint32_t seed = 0; seed < 12; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    const Scene scene = testing::randomScene(seed, 60 + 20 * seed, seed % 4, -1.0 + 0.2 * seed, 2.0);
    const Box b = *sceneBounds(scene);
    const Vec3 mid = (b.lo + b.hi) * 0.5;
    const double size = length(b.hi - b.lo);
    const OverlapMethod methods[] = {OverlapMethod::Exact, OverlapMethod::Sat, OverlapMethod::BBox};
    VoxelizeOptions o;
    o.method = methods[seed % 3];
    o.dims = {1 + uint32_t(u(rng) * 20), 1 + uint32_t(u(rng) * 20), 1 + uint32_t(u(rng) * 20)};
    const Grid grid = voxelizeScene(scene, o);
    const Accel g = buildAccel(scene, grid, AccelKind::Grid);
    const Accel n = buildAccel(scene, grid, AccelKind::None);
    for (int cam = 0; cam < 4; ++cam) {
      Camera c;
      const bool inside = cam % 2 == 1;
      c.center = inside ? b.lo + mul(b.hi - b.lo, Vec3{u(rng), u(rng), u(rng)}) : mid + randomUnit(rng) * (size * 1.5);
      c.direction = inside ? randomUnit(rng) : mid - c.center;
      c.up = randomUnit(rng);
      c.fovDegrees = 20 + 70 * u(rng);
      if (cam == 2) {
        c.kind = CameraKind::Orthographic;
        c.orthoHeight = size * 0.8;
      }
      const std::string what = "seed " + std::to_string(seed) + " camera " + std::to_string(cam);
      const std::vector<Ray> rays = tiledPrimaryRays(c, 48, 8);
      const PacketCheck check = expectPacketsMatch(g, n, rays, 64, what);
      if (::testing::Test::HasFailure()) return;
      // Coherent packets really took the slice walk, which visits each cell once per packet.
      if (check.hits > 100) {
        EXPECT_LT(check.packetCells, check.rayCells) << what;
      }
      // Odd packet sizes, and the same rays shuffled (incoherent packets fall back to single rays).
      expectPacketsMatch(g, n, rays, 13, what + " packets of 13");
      std::vector<Ray> shuffled = rays;
      std::shuffle(shuffled.begin(), shuffled.end(), rng);
      expectPacketsMatch(g, n, shuffled, 64, what + " shuffled");
      if (::testing::Test::HasFailure()) return;
    }
  }
}

// Shadow-like packets: rays from many points towards one light, with tMin and tMax windows.
TEST(TracePacket, WindowedRaysTowardsAPoint) {
  const Scene scene = testing::randomScene(31, 300, 3, 0, 1);
  VoxelizeOptions o;
  o.dims = {12, 9, 14};
  const Grid grid = voxelizeScene(scene, o);
  const Accel g = buildAccel(scene, grid, AccelKind::Grid);
  const Accel n = buildAccel(scene, grid, AccelKind::None);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const Vec3 light{0.5, 3, 0.4};
  std::vector<Ray> rays;
  for (int i = 0; i < 64 * 40; ++i) {
    const Vec3 p{0.3 + 0.05 * u(rng), u(rng) * 0.05, 0.3 + 0.05 * u(rng)};
    const Vec3 d = light - p;
    rays.push_back(Ray{p, d, 0.01 + 0.3 * u(rng), 0.5 + 0.5 * u(rng)});
  }
  expectPacketsMatch(g, n, rays, 64, "windowed");
}

// Packets of rays exactly along cell faces and edges, with +-0, -0.0 and 1e-30 components, at integer boundaries;
// also scaled to 1e-6 and moved 1e7 away.
TEST(TracePacket, RaysAlongFacesEdgesAndCorners) {
  const int n = 8;
  struct Case {
    double scale;
    Vec3 offset;
  };
  for (const Case& c : {Case{1, {}}, Case{1e-6, {}}, Case{1, {1e7, -1e7, 1e7}}, Case{1e-6, {3, 3, 3}}}) {
    const Scene scene = testing::latticeScene(n, c.scale, c.offset);
    const Grid grid = testing::latticeGrid(scene, n, c.scale, c.offset);
    const Accel g = buildAccel(scene, grid, AccelKind::Grid);
    const Accel none = buildAccel(scene, grid, AccelKind::None);
    // specialRays lists rays in groups that share a direction: packets of them are coherent.
    const std::vector<Ray> rays = testing::specialRays(n, c.scale, c.offset);
    for (uint32_t size : {2u, 6u, 64u})
      expectPacketsMatch(g, none, rays, size, "special rays, scale " + std::to_string(c.scale));
    // Orthographic packets along each axis, on the cell lattice and a hair off it.
    std::vector<Ray> lattice;
    for (int axis = 0; axis < 3; ++axis)
      for (double sign : {1.0, -1.0})
        for (double jitter : {0.0, 1e-12, -1e-9})
          for (int j = 0; j <= n; ++j)
            for (int i = 0; i <= n; ++i) {
              Vec3 o, d;
              o.at(axis) = sign > 0 ? -2 : n + 2;
              o.at((axis + 1) % 3) = i + jitter;
              o.at((axis + 2) % 3) = j * 0.5;
              d.at(axis) = sign;
              d.at((axis + 1) % 3) = jitter == 0 ? -0.0 : 1e-30;
              lattice.push_back(Ray{c.offset + o * c.scale, d});
            }
    const PacketCheck check = expectPacketsMatch(g, none, lattice, 64, "lattice, scale " + std::to_string(c.scale));
    EXPECT_GT(check.hits, 100u);
  }
}

// A tilted mesh whose vertices lie on the integer lattice, hit by orthographic packets whose rays run exactly through
// vertices and along edges: the packets' outer rays touch triangles of the neighbouring packets only on their
// boundary, where frustum culling must keep them (a vertex shared by six triangles goes to the smallest id).
TEST(TracePacket, RaysThroughSharedVerticesAndEdgesAtPacketBorders) {
  const int n = 16;
  Scene scene;
  scene.materials.push_back({});
  const auto vertex = [](int i, int j) { return Vec3{double(i), double(j), 0.25 * i - 0.5 * j}; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      scene.triangles.push_back(Triangle{{vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)}});
      scene.triangles.push_back(Triangle{{vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)}});
    }
  for (const std::array<uint32_t, 3>& dims : {std::array<uint32_t, 3>{16, 16, 4}, std::array<uint32_t, 3>{5, 7, 3}}) {
    VoxelizeOptions o;
    o.dims = dims;
    const Grid grid = voxelizeScene(scene, o);
    const Accel g = buildAccel(scene, grid, AccelKind::Grid);
    const Accel none = buildAccel(scene, grid, AccelKind::None);
    for (double step : {1.0, 0.5}) {
      std::vector<Ray> rays;
      for (double ty = 0; ty < n; ty += 8 * step)
        for (double tx = 0; tx < n; tx += 8 * step)
          for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) rays.push_back(Ray{{tx + x * step, ty + y * step, 20}, {-0.0, 0, -1}});
      const PacketCheck check = expectPacketsMatch(g, none, rays, 64, "lattice step " + std::to_string(step));
      EXPECT_EQ(check.hits, rays.size());
    }
  }
}

// The single-ray walk's hardest stop decision (traverse_test.cpp, NearCoincidentHitsOnBothSidesOfABoundary) in
// packets: triangle A lies in the slice boundary x = 2, triangle B (smaller ids) one ulp beyond it, in the next
// slice only; their t are equal or an ulp apart, so a ray must not retire after A's slice without the slacks.
TEST(TracePacket, NearCoincidentHitsOnBothSidesOfASliceBoundary) {
  std::mt19937 rng(29);
  int nearerBehind = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const bool forward = trial % 2 == 0;
    const testing::NearCoincidentPlanes c = testing::nearCoincidentPlanes(forward);
    const Accel g = buildAccel(c.scene, c.grid, AccelKind::Grid);
    const Accel none = buildAccel(c.scene, c.grid, AccelKind::None);
    const std::vector<Ray> rays = testing::raysAtNearCoincidentPlanes(rng, forward, 256);
    expectPacketsMatch(g, none, rays, 64, forward ? "B beyond +x" : "B beyond -x");
    for (const Ray& r : rays) nearerBehind += traceRay(none, r).prim <= 1;
  }
  EXPECT_GT(nearerBehind, 100);  // the case really occurs
}

TEST(TracePacket, OneCellAndLargeGrids) {
  // The small triangles of a random scene (the large ones, and spheres, would fill millions of cells at 2048 a side).
  Scene scene = testing::randomScene(8, 200, 0);
  std::erase_if(scene.triangles, [](const Triangle& t) {
    const Vec3 e = maxVec(maxVec(t.v[0], t.v[1]), t.v[2]) - minVec(minVec(t.v[0], t.v[1]), t.v[2]);
    return std::max({e.x, e.y, e.z}) > 0.1;
  });
  const Box b = *sceneBounds(scene);
  const Vec3 mid = (b.lo + b.hi) * 0.5;
  Camera c;
  c.center = mid + Vec3{0.3, 0.4, 2.5};
  c.direction = mid - c.center;
  for (const std::array<uint32_t, 3>& dims :
       {std::array<uint32_t, 3>{1, 1, 1}, std::array<uint32_t, 3>{2048, 2048, 2048},
        std::array<uint32_t, 3>{1, 700, 3}}) {
    VoxelizeOptions o;
    o.dims = dims;
    const Grid grid = voxelizeScene(scene, o);
    const Accel g = buildAccel(scene, grid, AccelKind::Grid);
    const Accel n = buildAccel(scene, grid, AccelKind::None);
    expectPacketsMatch(g, n, tiledPrimaryRays(c, 40, 8), 64,
                       "grid " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]));
  }
}

TEST(TracePacket, DegenerateRaysAndSizes) {
  const Scene scene = testing::randomScene(2, 50, 2);
  VoxelizeOptions o;
  o.dims = {5, 5, 5};
  const Grid grid = voxelizeScene(scene, o);
  const Accel g = buildAccel(scene, grid, AccelKind::Grid);
  const Accel n = buildAccel(scene, grid, AccelKind::None);
  std::vector<Ray> rays(64, Ray{{0.5, 0.5, 3}, {0.01, 0.02, -1}});
  rays[3].direction = {0, 0, 0};
  rays[7].direction = {std::nan(""), 0, -1};
  rays[9].origin = {kInfinity, 0, 0};
  rays[11].tMax = std::nan("");
  expectPacketsMatch(g, n, rays, 64, "degenerate members");
  // All rays well-formed but one with the opposite direction: the packet falls back and still matches.
  std::vector<Ray> mixed(20, Ray{{0.5, 0.5, 3}, {0.01, 0.02, -1}});
  mixed[4].direction = {0, 0, 1};
  expectPacketsMatch(g, n, mixed, 20, "mixed directions");
  std::vector<Hit> none;
  tracePacket(g, {}, none);  // an empty packet is fine
  std::vector<Hit> tooFew(1);
  EXPECT_THROW(tracePacket(g, rays, tooFew), vox::Error);
  bool oneAnswer[1];
  EXPECT_THROW(occludedPacket(g, rays, oneAnswer), vox::Error);
}

}  // namespace
}  // namespace vox
