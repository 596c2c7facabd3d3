// Primary-ray throughput of the grid against Embree 3 on the same triangles, camera and thread count.
//   bench_trace [--threads N] [--size N] [--reps N] [--factor F ...] [SCENE ...]
// Default scenes: the 40k seed bunny, the 69k Stanford bunny (PLY), the 115k SheenCloth. For each scene it voxelizes
// (exact) at each cells-per-triangle factor and traces size x size primary rays from defaultCamera(bounds) with
// rtcIntersect1, rtcIntersect8 (coherent context, 4x2 pixel packets), vox::traceRay (one ray at a time) and
// vox::tracePacket (8x8 pixel packets, as vox-trace renders). rtcIntersect1 and traceRay take the rays in the same
// order as the packets, tile after tile. The methods take turns, `reps` rounds, and each keeps
// its best time, so that a burst of load on a shared machine hits them alike. Prints rays per second, the ratios
// ours / Embree, cells and tests per ray, and how many pixels hit the same triangle as Embree and as traceRay.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "vox/trace/accel.h"
#include "vox/import/import.h"
#include "vox/trace/render.h"
#include "vox/trace/trace_packet.h"
#include "vox/trace/traverse.h"
#include "vox/voxelize/voxelize.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Method {
  std::string name;
  std::function<void()> run;
  double best = 1e30;
};

void timeInTurns(std::vector<Method>& methods, int reps) {
  for (int r = 0; r < reps; ++r)
    for (Method& m : methods) {
      const auto t0 = Clock::now();
      m.run();
      m.best = std::min(m.best, std::chrono::duration<double>(Clock::now() - t0).count());
    }
}

// The rays in the order vox-trace makes them: 8x8 pixel tiles, tile after tile (pixel[i] is the pixel of ray i).
struct TiledRays {
  std::vector<vox::Ray> rays;
  std::vector<uint64_t> pixel;
  std::vector<uint32_t> tileStart;  // first ray of each tile, and the end
};
TiledRays tileRays(const std::vector<vox::Ray>& rays, uint32_t size) {
  TiledRays t;
  for (uint32_t y0 = 0; y0 < size; y0 += 8)
    for (uint32_t x0 = 0; x0 < size; x0 += 8) {
      t.tileStart.push_back(uint32_t(t.rays.size()));
      for (uint32_t y = y0; y < std::min(y0 + 8, size); ++y)
        for (uint32_t x = x0; x < std::min(x0 + 8, size); ++x) {
          t.pixel.push_back(uint64_t(y) * size + x);
          t.rays.push_back(rays[t.pixel.back()]);
        }
    }
  t.tileStart.push_back(uint32_t(t.rays.size()));
  return t;
}

// One tile through vox::tracePacket; hits in tile order.
void tracePackets(const vox::Accel& accel, const TiledRays& tiled, size_t tile, vox::Hit* hits, vox::TraceStats* stats) {
  const uint32_t begin = tiled.tileStart[tile], count = tiled.tileStart[tile + 1] - begin;
  vox::tracePacket(accel, {tiled.rays.data() + begin, count}, {hits + begin, count}, stats);
}

std::array<uint32_t, 3> dimsForFactor(const vox::Box& b, size_t triangles, double factor) {
  const vox::Vec3 e = b.hi - b.lo;
  const double volume = std::max(e.x, 1e-30) * std::max(e.y, 1e-30) * std::max(e.z, 1e-30);
  const double cell = std::cbrt(volume / (factor * double(triangles)));
  std::array<uint32_t, 3> d;
  for (int a = 0; a < 3; ++a) d[a] = uint32_t(std::clamp(std::ceil(e[a] / cell), 1.0, 4096.0));
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  unsigned threads = 1;
  uint32_t size = 1024;
  int reps = 7;
  std::vector<double> factors;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc) threads = unsigned(std::atoi(argv[++i]));
    else if (a == "--size" && i + 1 < argc) size = uint32_t(std::atoi(argv[++i]));
    else if (a == "--reps" && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (a == "--factor" && i + 1 < argc) factors.push_back(std::atof(argv[++i]));
    else scenes.push_back(a);
  }
  if (factors.empty()) factors = {0.5, 1, 2, 3};
  if (scenes.empty())
    scenes = {std::string(VOX_SEED_DIR) + "/6837/scenes/bunny_40k.obj", std::string(VOX_SEED_DIR) + "/meshes/bun_zipper.ply",
              std::string(VOX_SEED_DIR) + "/meshes/derived/sheencloth_115k.obj"};
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  std::printf("threads: %u, image: %ux%u primary rays, best of %d rounds taken in turns\n", threads, size, size, reps);

  for (const std::string& path : scenes) {
    const vox::Scene scene = vox::loadScene(path);
    const vox::Box bounds = *vox::sceneBounds(scene);
    const vox::Camera cam = vox::defaultCamera(bounds);
    const uint64_t rayCount = uint64_t(size) * size;
    std::vector<vox::Ray> rays(rayCount);
    for (uint32_t y = 0; y < size; ++y)
      for (uint32_t x = 0; x < size; ++x) rays[uint64_t(y) * size + x] = vox::primaryRay(cam, size, size, x + 0.5, y + 0.5);

    // Embree: the same triangles as floats.
    const std::string config = "threads=" + std::to_string(threads);
    RTCDevice device = rtcNewDevice(config.c_str());
    RTCScene es = rtcNewScene(device);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const size_t nt = scene.triangles.size();
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * nt));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        const vox::Vec3& v = scene.triangles[t].v[k];
        vb[9 * t + 3 * k] = float(v.x), vb[9 * t + 3 * k + 1] = float(v.y), vb[9 * t + 3 * k + 2] = float(v.z);
        ib[3 * t + k] = unsigned(3 * t + k);
      }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(es, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(es);

    const TiledRays tiled = tileRays(rays, size);
    const size_t tileCount = tiled.tileStart.size() - 1;
    std::vector<Method> methods;
    std::vector<unsigned> embreeHit(rayCount);
    methods.push_back({"embree rtcIntersect1", [&] {
      tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rayCount, 1024), [&](const tbb::blocked_range<uint64_t>& r) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (uint64_t i = r.begin(); i < r.end(); ++i) {
          const vox::Ray& ray = tiled.rays[i];
          RTCRayHit rh{};
          rh.ray.org_x = float(ray.origin.x), rh.ray.org_y = float(ray.origin.y), rh.ray.org_z = float(ray.origin.z);
          rh.ray.dir_x = float(ray.direction.x), rh.ray.dir_y = float(ray.direction.y), rh.ray.dir_z = float(ray.direction.z);
          rh.ray.tnear = 0, rh.ray.tfar = INFINITY, rh.ray.mask = unsigned(-1);
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          rtcIntersect1(es, &ctx, &rh);
          embreeHit[tiled.pixel[i]] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? vox::kNoPrim : rh.hit.primID;
        }
      });
    }});
    // Packets of 8: 4x2 pixel blocks, coherent context.
    methods.push_back({"embree rtcIntersect8 coherent", [&] {
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, size / 2), [&](const tbb::blocked_range<uint32_t>& rows) {
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        alignas(32) RTCRayHit8 rh;
        alignas(32) int valid[8];
        for (uint32_t by = rows.begin(); by < rows.end(); ++by)
          for (uint32_t bx = 0; bx + 4 <= size; bx += 4) {
            for (int k = 0; k < 8; ++k) {
              const vox::Ray& ray = rays[uint64_t(2 * by + k / 4) * size + bx + k % 4];
              valid[k] = -1;
              rh.ray.org_x[k] = float(ray.origin.x), rh.ray.org_y[k] = float(ray.origin.y), rh.ray.org_z[k] = float(ray.origin.z);
              rh.ray.dir_x[k] = float(ray.direction.x), rh.ray.dir_y[k] = float(ray.direction.y), rh.ray.dir_z[k] = float(ray.direction.z);
              rh.ray.tnear[k] = 0, rh.ray.tfar[k] = INFINITY, rh.ray.mask[k] = unsigned(-1), rh.ray.time[k] = 0, rh.ray.flags[k] = 0;
              rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            }
            rtcIntersect8(valid, es, &ctx, &rh);
          }
      });
    }});

    struct Variant {
      std::unique_ptr<vox::Grid> grid;
      std::unique_ptr<vox::Accel> accel;
      double factor = 0, voxelizeSeconds = 0;
      std::vector<uint32_t> single;
      std::vector<vox::Hit> packet;
    };
    std::vector<Variant> variants(factors.size());
    for (size_t f = 0; f < factors.size(); ++f) {
      Variant& v = variants[f];
      v.factor = factors[f];
      vox::VoxelizeOptions vo;
      vo.dims = dimsForFactor(bounds, nt, v.factor);
      const auto v0 = Clock::now();
      v.grid = std::make_unique<vox::Grid>(vox::voxelizeScene(scene, vo));
      v.voxelizeSeconds = std::chrono::duration<double>(Clock::now() - v0).count();
      v.accel = std::make_unique<vox::Accel>(vox::buildAccel(scene, *v.grid, vox::AccelKind::Grid));
      v.single.resize(rayCount);
      v.packet.resize(rayCount);
      methods.push_back({"grid traceRay", [&v, &tiled, rayCount] {
        tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rayCount, 1024), [&](const tbb::blocked_range<uint64_t>& r) {
          for (uint64_t i = r.begin(); i < r.end(); ++i) v.single[tiled.pixel[i]] = vox::traceRay(*v.accel, tiled.rays[i]).prim;
        });
      }});
      methods.push_back({"grid tracePacket", [&v, &tiled, tileCount] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, tileCount, 16), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t tile = r.begin(); tile < r.end(); ++tile) tracePackets(*v.accel, tiled, tile, v.packet.data(), nullptr);
        });
      }});
    }
    timeInTurns(methods, reps);
    rtcReleaseScene(es);
    rtcReleaseDevice(device);

    const double e1 = methods[0].best, e8 = methods[1].best;
    const char* name = std::strrchr(path.c_str(), '/') ? std::strrchr(path.c_str(), '/') + 1 : path.c_str();
    std::printf("\n%s: %zu triangles\n", name, nt);
    std::printf("  embree rtcIntersect1:            %8.2f Mrays/s\n", rayCount / e1 / 1e6);
    std::printf("  embree rtcIntersect8 coherent:   %8.2f Mrays/s\n", rayCount / e8 / 1e6);
    for (size_t f = 0; f < variants.size(); ++f) {
      const Variant& v = variants[f];
      const double g = methods[2 + 2 * f].best, gp = methods[3 + 2 * f].best;
      vox::TraceStats st, pst;
      for (uint64_t i = 0; i < rayCount; i += 97) vox::traceRay(*v.accel, rays[i], &st);
      std::vector<vox::Hit> scratch(rayCount);
      for (size_t tile = 0; tile < tileCount; tile += 7) tracePackets(*v.accel, tiled, tile, scratch.data(), &pst);
      uint64_t same = 0, packetSame = 0, hits = 0;
      for (uint64_t i = 0; i < rayCount; ++i) {
        same += v.single[i] == embreeHit[i];
        packetSame += v.packet[i].prim == v.single[tiled.pixel[i]];
        hits += v.single[i] != vox::kNoPrim;
      }
      std::printf("  grid %4ux%4ux%4u (%.1f cells/tri, voxelize %.2f s), %.1f%% of rays hit\n", v.grid->dims[0],
                  v.grid->dims[1], v.grid->dims[2], v.factor, v.voxelizeSeconds, 100.0 * hits / rayCount);
      std::printf("    traceRay:    %8.2f Mrays/s  ratio vs rtcIntersect1 %.3f, vs rtcIntersect8 %.3f  cells/ray %.2f "
                  "tests/ray %.2f  same prim as embree %.3f%%\n",
                  rayCount / g / 1e6, e1 / g, e8 / g, double(st.cells) / st.rays, double(st.tests) / st.rays,
                  100.0 * same / rayCount);
      std::printf("    tracePacket: %8.2f Mrays/s  ratio vs rtcIntersect1 %.3f, vs rtcIntersect8 %.3f  cells/ray %.2f "
                  "tests/ray %.2f  same prim as traceRay %.3f%%\n",
                  rayCount / gp / 1e6, e1 / gp, e8 / gp, double(pst.cells) / pst.rays, double(pst.tests) / pst.rays,
                  100.0 * packetSame / rayCount);
      std::fflush(stdout);
    }
  }
  return 0;
}
