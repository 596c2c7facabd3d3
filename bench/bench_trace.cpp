// Ray throughput of the grid against Embree 3 on the same triangles, rays and thread count.
//   bench_trace [--threads N] [--size N] [--reps N] [--factor F ...] [--incoherent [--ours-only]] [SCENE ...]
// (--factor with --incoherent: the grid at each cells-per-triangle factor instead of the default grid)
// Default scenes: the 40k seed bunny, the 69k Stanford bunny (PLY), the 115k SheenCloth.
// Primary rays (default): for each scene it voxelizes (exact) at each cells-per-triangle factor and traces size x size
// primary rays from defaultCamera(bounds) with rtcIntersect1, rtcIntersect8 (coherent context, 4x2 pixel packets),
// rtcIntersect1M (the stream call, an 8x8 tile's rays at a time, coherent context),
// vox::traceRay (one ray at a time) and vox::tracePacket (8x8 pixel packets, as vox-trace renders). rtcIntersect1 and
// traceRay take the rays in the same order as the packets, tile after tile. Prints rays per second, the ratios
// ours / Embree, cells and tests per ray, and how many pixels hit the same triangle as Embree and as traceRay.
// Incoherent rays (--incoherent, issue 12): secondary rays from the first hits of those primary rays, on the grid
// vox-voxelize makes by default (planGrid): reflection, cosine-weighted hemisphere rays (closest hit, unbounded),
// ambient-occlusion rays (the same directions, occlusion within a radius) and shadow rays to a point light, through
// rtcIntersect1 / rtcOccluded1 and vox::traceRay / vox::occluded. Outside the timed runs, every ray's result is
// compared with Embree's (same triangle, or t within float tolerance; same occluded flag) and a sample with the
// brute force (--accel none), bit for bit; and our walk without the float filter (every triangle tested in double,
// the `double only` column: its time over ours) is timed in the same turns and checked equal. The yardstick of the
// goal: the textbook walk (textbook_walk.h: no tolerances, same cells, filter and tests; `textbook/embree`, with how
// many of its results differ from ours) and that walk alone over the cells up to each ray's nearest hit, no test
// (`walk alone`: Embree's time over its time).
// The methods take turns, `reps` rounds, so that a burst of load on a shared machine hits them alike; each keeps its
// best and median time.
#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "vox/trace/accel.h"
#include "vox/import/import.h"
#include "vox/trace/render.h"
#include "vox/trace/trace_packet.h"
#include "vox/trace/traverse.h"
#include "vox/voxelize/voxelize.h"
#include "textbook_walk.h"

namespace {

using Clock = std::chrono::steady_clock;

struct Method {
  Method(std::string n, std::function<void()> r) : name(std::move(n)), run(std::move(r)) {}
  std::string name;
  std::function<void()> run;
  double best = 1e30;
  std::vector<double> times, cpuTimes;  // wall seconds; process CPU seconds (what a loaded machine distorts less)

  double median(bool cpu = false) const {
    std::vector<double> t = cpu ? cpuTimes : times;
    std::sort(t.begin(), t.end());
    return t.empty() ? 0 : t.size() % 2 ? t[t.size() / 2] : (t[t.size() / 2 - 1] + t[t.size() / 2]) / 2;
  }
};

void timeInTurns(std::vector<Method>& methods, int reps) {
  for (int r = 0; r < reps; ++r)
    for (Method& m : methods) {
      const std::clock_t c0 = std::clock();
      const auto t0 = Clock::now();
      m.run();
      const double t = std::chrono::duration<double>(Clock::now() - t0).count();
      m.cpuTimes.push_back(double(std::clock() - c0) / CLOCKS_PER_SEC);
      m.best = std::min(m.best, t);
      m.times.push_back(t);
    }
}

// The scene's triangles as floats in an Embree scene: one geometry, primID = our triangle id.
struct EmbreeScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  EmbreeScene(const vox::Scene& s, unsigned threads) {
    const std::string config = "threads=" + std::to_string(threads);
    device = rtcNewDevice(config.c_str());
    scene = rtcNewScene(device);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    const size_t nt = s.triangles.size();
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * nt));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
    for (size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        const vox::Vec3& v = s.triangles[t].v[k];
        vb[9 * t + 3 * k] = float(v.x), vb[9 * t + 3 * k + 1] = float(v.y), vb[9 * t + 3 * k + 2] = float(v.z);
        ib[3 * t + k] = unsigned(3 * t + k);
      }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
};

// The rays in the order vox-trace makes them: 8x8 pixel tiles, tile after tile (pixel[i] is the pixel of ray i).
// One Embree ray from ours, converted to float (in every timed loop, as each method converts its own rays).
RTCRayHit embreeRayHit(const vox::Ray& ray, float tnear, float tfar) {
  RTCRayHit rh{};
  rh.ray.org_x = float(ray.origin.x), rh.ray.org_y = float(ray.origin.y), rh.ray.org_z = float(ray.origin.z);
  rh.ray.dir_x = float(ray.direction.x), rh.ray.dir_y = float(ray.direction.y), rh.ray.dir_z = float(ray.direction.z);
  rh.ray.tnear = tnear, rh.ray.tfar = tfar, rh.ray.mask = unsigned(-1);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

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
void tracePackets(const vox::Accel& accel, const TiledRays& tiled, size_t tile, vox::Hit* hits,
                  vox::TraceStats* stats) {
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

// Primary rays at each cells-per-triangle factor (the table of docs/speed.md, "Tracing primary rays").
void benchPrimary(const std::string& path, unsigned threads, uint32_t size, int reps,
                  const std::vector<double>& factors) {
  const vox::Scene scene = vox::loadScene(path);
  const vox::Box bounds = *vox::sceneBounds(scene);
  const vox::Camera cam = vox::defaultCamera(bounds);
  const uint64_t rayCount = uint64_t(size) * size;
  std::vector<vox::Ray> rays(rayCount);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x)
      rays[uint64_t(y) * size + x] = vox::primaryRay(cam, size, size, x + 0.5, y + 0.5);

  // Embree: the same triangles as floats.
  const EmbreeScene embree(scene, threads);
  const RTCScene es = embree.scene;
  const size_t nt = scene.triangles.size();

  const TiledRays tiled = tileRays(rays, size);
  const size_t tileCount = tiled.tileStart.size() - 1;
  std::vector<Method> methods;
  std::vector<unsigned> embreeHit(rayCount);
  methods.push_back(
      {"embree rtcIntersect1", [&] {
         tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rayCount, 1024), [&](const tbb::blocked_range<uint64_t>& r) {
           RTCIntersectContext ctx;
           rtcInitIntersectContext(&ctx);
           for (uint64_t i = r.begin(); i < r.end(); ++i) {
             const vox::Ray& ray = tiled.rays[i];
             RTCRayHit rh = embreeRayHit(ray, 0, INFINITY);
             rtcIntersect1(es, &ctx, &rh);
             embreeHit[tiled.pixel[i]] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? vox::kNoPrim : rh.hit.primID;
           }
         });
       }});
  // Packets of 8: 4x2 pixel blocks, coherent context.
  methods.push_back({"embree rtcIntersect8 coherent", [&] {
                       tbb::parallel_for(
                           tbb::blocked_range<uint32_t>(0, size / 2), [&](const tbb::blocked_range<uint32_t>& rows) {
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
                                   rh.ray.org_x[k] = float(ray.origin.x), rh.ray.org_y[k] = float(ray.origin.y),
                                   rh.ray.org_z[k] = float(ray.origin.z);
                                   rh.ray.dir_x[k] = float(ray.direction.x), rh.ray.dir_y[k] = float(ray.direction.y),
                                   rh.ray.dir_z[k] = float(ray.direction.z);
                                   rh.ray.tnear[k] = 0, rh.ray.tfar[k] = INFINITY, rh.ray.mask[k] = unsigned(-1),
                                   rh.ray.time[k] = 0, rh.ray.flags[k] = 0;
                                   rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                                 }
                                 rtcIntersect8(valid, es, &ctx, &rh);
                               }
                           });
                     }});

  // The stream call (what Open3D's RaycastingScene uses): each 8x8 tile's rays as one array, coherent context.
  std::vector<unsigned> streamHit(rayCount);
  methods.push_back(
      {"embree rtcIntersect1M coherent", [&] {
         tbb::parallel_for(tbb::blocked_range<size_t>(0, tileCount, 16), [&](const tbb::blocked_range<size_t>& r) {
           RTCIntersectContext ctx;
           rtcInitIntersectContext(&ctx);
           ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
           RTCRayHit rh[64];
           for (size_t tile = r.begin(); tile < r.end(); ++tile) {
             const uint32_t b = tiled.tileStart[tile], e = tiled.tileStart[tile + 1];
             for (uint32_t i = b; i < e; ++i) rh[i - b] = embreeRayHit(tiled.rays[i], 0, INFINITY);
             rtcIntersect1M(es, &ctx, rh, e - b, sizeof(RTCRayHit));
             for (uint32_t i = b; i < e; ++i)
               streamHit[tiled.pixel[i]] =
                   rh[i - b].hit.geomID == RTC_INVALID_GEOMETRY_ID ? vox::kNoPrim : rh[i - b].hit.primID;
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
                         tbb::parallel_for(tbb::blocked_range<uint64_t>(0, rayCount, 1024),
                                           [&](const tbb::blocked_range<uint64_t>& r) {
                                             for (uint64_t i = r.begin(); i < r.end(); ++i)
                                               v.single[tiled.pixel[i]] = vox::traceRay(*v.accel, tiled.rays[i]).prim;
                                           });
                       }});
    methods.push_back({"grid tracePacket", [&v, &tiled, tileCount] {
                         tbb::parallel_for(tbb::blocked_range<size_t>(0, tileCount, 16),
                                           [&](const tbb::blocked_range<size_t>& r) {
                                             for (size_t tile = r.begin(); tile < r.end(); ++tile)
                                               tracePackets(*v.accel, tiled, tile, v.packet.data(), nullptr);
                                           });
                       }});
  }
  timeInTurns(methods, reps);

  const double e1 = methods[0].best, e8 = methods[1].best, e1m = methods[2].best;
  uint64_t streamSame = 0;
  for (uint64_t i = 0; i < rayCount; ++i) streamSame += streamHit[i] == embreeHit[i];
  const char* name = std::strrchr(path.c_str(), '/') ? std::strrchr(path.c_str(), '/') + 1 : path.c_str();
  std::printf("\n%s: %zu triangles\n", name, nt);
  std::printf("  embree rtcIntersect1:            %8.2f Mrays/s\n", rayCount / e1 / 1e6);
  std::printf("  embree rtcIntersect8 coherent:   %8.2f Mrays/s\n", rayCount / e8 / 1e6);
  std::printf("  embree rtcIntersect1M coherent:  %8.2f Mrays/s  (same prim as rtcIntersect1 %.3f%%)\n",
              rayCount / e1m / 1e6, 100.0 * streamSame / rayCount);
  for (size_t f = 0; f < variants.size(); ++f) {
    const Variant& v = variants[f];
    const double g = methods[3 + 2 * f].best, gp = methods[4 + 2 * f].best;
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
    std::printf(
        "    traceRay:    %8.2f Mrays/s  ratio vs rtcIntersect1 %.3f, vs rtcIntersect8 %.3f  cells/ray %.2f "
        "tests/ray %.2f  same prim as embree %.3f%%\n",
        rayCount / g / 1e6, e1 / g, e8 / g, double(st.cells) / st.rays, double(st.tests) / st.rays,
        100.0 * same / rayCount);
    std::printf(
        "    tracePacket: %8.2f Mrays/s  ratio vs rtcIntersect1 %.3f, vs rtcIntersect8 %.3f, vs rtcIntersect1M %.3f  "
        "cells/ray %.2f tests/ray %.2f  same prim as traceRay %.3f%%\n",
        rayCount / gp / 1e6, e1 / gp, e8 / gp, e1m / gp, double(pst.cells) / pst.rays, double(pst.tests) / pst.rays,
        100.0 * packetSame / rayCount);
    std::fflush(stdout);
  }
}

// ---- Incoherent rays (issue 12) ----

// SplitMix64 (Steele et al. 2014): a deterministic stream per ray, so the ray sets do not depend on threads.
struct SplitMix {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
};

// One set of secondary rays; `occlusion` sets are any-hit queries (rtcOccluded1 / vox::occluded).
struct RaySet {
  std::string name;
  bool occlusion = false;
  std::vector<vox::Ray> rays;
};

// Cosine-weighted direction about the unit normal n (Malley's method), unit length.
vox::Vec3 hemisphereDirection(const vox::Vec3& n, SplitMix& rng) {
  const vox::Vec3 helper = std::fabs(n.x) > 0.5 ? vox::Vec3{0, 1, 0} : vox::Vec3{1, 0, 0};
  const vox::Vec3 u = vox::normalize(vox::cross(helper, n)), v = vox::cross(n, u);
  const double r = std::sqrt(rng.uniform()), phi = 2 * M_PI * rng.uniform();
  const double h = std::sqrt(std::max(0.0, 1 - r * r));
  return vox::normalize(u * (r * std::cos(phi)) + v * (r * std::sin(phi)) + n * h);
}

// Secondary rays from the first hits of `primary` (traced with traceRay): for every hit, one reflection ray, one
// hemisphere ray (closest hit, unbounded), one ambient-occlusion ray (the same direction, occlusion within a fifth of
// the bounds' diagonal) and one shadow ray to a point light above and beside the bounds. Origins are lifted off the
// surface by 1e-5 of the diagonal along the normal facing the incoming ray, far above float rounding at these
// scales, so that neither tracer hits the surface it starts from.
std::vector<RaySet> secondaryRays(const vox::Accel& accel, const std::vector<vox::Ray>& primary, const vox::Box& b) {
  std::vector<RaySet> sets = {
      {"reflection", false, {}}, {"hemisphere", false, {}}, {"ao", true, {}}, {"shadow", true, {}}};
  const vox::Vec3 extent = b.hi - b.lo, centre = (b.lo + b.hi) * 0.5;
  const double diag = vox::length(extent), lift = 1e-5 * diag;
  const vox::Vec3 light = centre + vox::Vec3{0.6, 1.4, 0.9} * diag;
  for (size_t i = 0; i < primary.size(); ++i) {
    const vox::Ray& ray = primary[i];
    const vox::Hit hit = vox::traceRay(accel, ray);
    if (!hit.valid() || hit.prim >= accel.triangleCount) continue;
    const vox::Vec3 d = vox::normalize(ray.direction);
    vox::Vec3 n = vox::triangleNormal(accel.triangles[hit.prim]);
    if (vox::dot(n, d) > 0) n = -n;
    const vox::Vec3 o = ray.origin + ray.direction * hit.t + n * lift;
    SplitMix rng{0x5eedull * (i + 1)};
    const vox::Vec3 h = hemisphereDirection(n, rng);
    sets[0].rays.push_back({o, d - n * (2 * vox::dot(d, n)), 0, vox::kInfinity});
    sets[1].rays.push_back({o, h, 0, vox::kInfinity});
    sets[2].rays.push_back({o, h, 0, 0.2 * diag});
    sets[3].rays.push_back({o, light - o, 0, 1});
  }
  return sets;
}

// Embree's answer for ray i of a set: t (INFINITY on a miss) and primID, or the occluded flag as t = 0 / INFINITY.
struct EmbreeResult {
  float t = INFINITY;
  unsigned prim = vox::kNoPrim;
};
void embreeTrace(RTCScene es, const RaySet& set, std::vector<EmbreeResult>& out) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (size_t i = r.begin(); i < r.end(); ++i) {
      const vox::Ray& ray = set.rays[i];
      RTCRayHit rh = embreeRayHit(ray, float(ray.tMin), float(ray.tMax));
      if (set.occlusion) {
        rtcOccluded1(es, &ctx, &rh.ray);
        out[i] = {rh.ray.tfar < 0 ? 0.0f : INFINITY, vox::kNoPrim};
      } else {
        rtcIntersect1(es, &ctx, &rh);
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID)
          out[i] = {rh.ray.tfar, rh.hit.primID};
        else
          out[i] = {};
      }
    }
  });
}

// Ours, one ray at a time: vox::traceRay or vox::occluded (t = 0 / INFINITY for the flag).
void voxTrace(const vox::Accel& accel, const RaySet& set, std::vector<vox::Hit>& out) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) {
      if (set.occlusion)
        out[i] = vox::occluded(accel, set.rays[i]) ? vox::Hit{0, 0} : vox::Hit{};
      else
        out[i] = vox::traceRay(accel, set.rays[i]);
    }
  });
}

// The textbook walk (textbook_walk.h), compiled like our walks (one copy per instruction set, picked at load time).
#define VOX_BENCH_COPIES [[gnu::target_clones("arch=x86-64-v4", "avx2", "default"), gnu::flatten]]
VOX_BENCH_COPIES vox::Hit textbookNearest(const vox::Accel& accel, const vox::Ray& ray) {
  return textbook::trace<false>(accel, ray);
}
VOX_BENCH_COPIES bool textbookAny(const vox::Accel& accel, const vox::Ray& ray) {
  return textbook::trace<true>(accel, ray).valid();
}
VOX_BENCH_COPIES uint64_t textbookWalkOnly(const vox::Accel& accel, const vox::Ray& ray, double tStop) {
  return textbook::walkOnly(accel, ray, tStop);
}
#undef VOX_BENCH_COPIES

void textbookTrace(const vox::Accel& accel, const RaySet& set, std::vector<vox::Hit>& out) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i)
      out[i] = set.occlusion ? (textbookAny(accel, set.rays[i]) ? vox::Hit{0, 0} : vox::Hit{})
                             : textbookNearest(accel, set.rays[i]);
  });
}

// The textbook walk's cells up to each ray's nearest hit (`stopT`), looked up and not tested.
void textbookWalk(const vox::Accel& accel, const RaySet& set, const std::vector<double>& stopT,
                  std::atomic<uint64_t>& sink) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    uint64_t sum = 0;
    for (size_t i = r.begin(); i < r.end(); ++i) sum += textbookWalkOnly(accel, set.rays[i], stopT[i]);
    sink += sum;
  });
}

// Ours, as streams: runs of kMaxPacketRays consecutive rays of the set (neighbouring pixels' secondary rays) through
// vox::tracePacket / vox::occludedPacket, which trace rays that share no travel direction one by one.
void voxPackets(const vox::Accel& accel, const RaySet& set, std::vector<vox::Hit>& out) {
  const size_t packets = (set.rays.size() + vox::kMaxPacketRays - 1) / vox::kMaxPacketRays;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, packets, 16), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t p = r.begin(); p < r.end(); ++p) {
      const size_t begin = p * vox::kMaxPacketRays;
      const size_t count = std::min<size_t>(vox::kMaxPacketRays, set.rays.size() - begin);
      const std::span<const vox::Ray> rays(set.rays.data() + begin, count);
      if (set.occlusion) {
        bool blocked[vox::kMaxPacketRays];
        vox::occludedPacket(accel, rays, {blocked, count});
        for (size_t i = 0; i < count; ++i) out[begin + i] = blocked[i] ? vox::Hit{0, 0} : vox::Hit{};
      } else {
        vox::tracePacket(accel, rays, {out.data() + begin, count});
      }
    }
  });
}

// How many of two methods' results differ in primitive or in the bits of t.
uint64_t differingHits(const std::vector<vox::Hit>& a, const std::vector<vox::Hit>& b) {
  uint64_t n = 0;
  for (size_t i = 0; i < a.size(); ++i)
    n += a[i].prim != b[i].prim || std::memcmp(&a[i].t, &b[i].t, sizeof(double)) != 0;
  return n;
}

// How our results compare with Embree's: the same triangle (or both miss, or the same occluded flag), a different
// triangle at a t within float tolerance (coincident or adjacent surfaces, an edge hit), or a mismatch.
struct Agreement {
  uint64_t same = 0, closeT = 0, mismatch = 0;
};
Agreement compareWithEmbree(const RaySet& set, const std::vector<vox::Hit>& ours, const std::vector<EmbreeResult>& e,
                            double diag) {
  Agreement a;
  for (size_t i = 0; i < ours.size(); ++i) {
    const bool oursHit = ours[i].valid(), embreeHit = std::isfinite(e[i].t);
    if (set.occlusion || !oursHit || !embreeHit) {
      (oursHit == embreeHit ? a.same : a.mismatch)++;
    } else if (ours[i].prim == e[i].prim) {
      ++a.same;
    } else {
      // Embree works in float: its t carries a relative error of a few float ulps of the coordinates.
      const double len = vox::length(set.rays[i].direction);
      const double tol = 1e-5 * diag / len + 1e-5 * ours[i].t;
      (std::fabs(double(e[i].t) - ours[i].t) <= tol ? a.closeT : a.mismatch)++;
    }
  }
  return a;
}

// Every `stride`-th ray against the brute force (every primitive tested): t and primitive bit for bit.
uint64_t bruteForceDifferences(const vox::Accel& brute, const RaySet& set, const std::vector<vox::Hit>& ours,
                               size_t stride, uint64_t& checked) {
  std::atomic<uint64_t> diff{0}, count{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, set.rays.size() / stride), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k < r.end(); ++k) {
      const size_t i = k * stride;
      ++count;
      if (set.occlusion) {
        if (vox::occluded(brute, set.rays[i]) != ours[i].valid()) ++diff;
      } else {
        const vox::Hit h = vox::traceRay(brute, set.rays[i]);
        if (h.prim != ours[i].prim || std::memcmp(&h.t, &ours[i].t, sizeof(double)) != 0) ++diff;
      }
    }
  });
  checked = count;
  return diff;
}

// Secondary rays of one scene on its default grid: Embree against ours, same rays, results checked.
// `oursOnly` (--ours-only): times only our walk and checks nothing, for profiling where our time goes.
// `factor`: cells per triangle of the grid (dimsForFactor), or 0 for the default grid.
void benchIncoherent(const std::string& path, unsigned threads, uint32_t size, int reps, bool oursOnly, double factor) {
  const vox::Scene scene = vox::loadScene(path);
  const vox::Box bounds = *vox::sceneBounds(scene);
  const vox::Camera cam = vox::defaultCamera(bounds);
  std::vector<vox::Ray> primary(uint64_t(size) * size);
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x)
      primary[uint64_t(y) * size + x] = vox::primaryRay(cam, size, size, x + 0.5, y + 0.5);
  vox::VoxelizeOptions options;  // vox-voxelize's default grid unless a factor is given
  if (factor > 0) options.dims = dimsForFactor(bounds, scene.triangles.size(), factor);
  const vox::Grid grid = vox::voxelizeScene(scene, options);
  const vox::Accel accel = vox::buildAccel(scene, grid, vox::AccelKind::Grid);
  const vox::Accel brute = vox::buildAccel(scene, grid, vox::AccelKind::None);
  // The walk as before the float filter (Accel::floatCells): every triangle tested in double, read from the cell
  // copies (what a grid over the copies' budget does).
  vox::Accel byId = vox::buildAccel(scene, grid, vox::AccelKind::Grid);
  byId.floatCells = {};
  // The uniform walk (no cell boxes: every cell crossed is visited), the walk before issue 27.
  const vox::Accel uniform = vox::buildAccel(scene, grid, vox::AccelKind::Uniform);
  const std::vector<RaySet> sets = secondaryRays(accel, tileRays(primary, size).rays, bounds);
  const EmbreeScene embree(scene, threads);
  const double diag = vox::length(bounds.hi - bounds.lo);

  const char* name = std::strrchr(path.c_str(), '/') ? std::strrchr(path.c_str(), '/') + 1 : path.c_str();
  std::printf("\n%s: %zu triangles, %s grid %ux%ux%u, %zu secondary rays per set\n", name, scene.triangles.size(),
              factor > 0 ? ("cells/triangle " + std::to_string(factor).substr(0, 4)).c_str() : "default", grid.dims[0],
              grid.dims[1], grid.dims[2], sets[0].rays.size());
  // What the cell boxes cost on top of the uniform walk's structure (issue 27's build goal): their build alone, best
  // of 3 on a copy of the uniform accel (on the bench's threads, as buildAccel builds them), and their bytes.
  double boxSeconds = 1e300;
  for (int r = 0; r < 3; ++r) {
    vox::Accel copy = uniform;
    const auto t0 = Clock::now();
    vox::buildCellBoxes(copy);
    boxSeconds = std::min(boxSeconds, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  const double tableBytes = double(accel.blockSlot.size() + accel.cellSlots.size()) * sizeof(uint32_t) +
                            double(accel.emptyShift.size()) +
                            double(accel.floatCells.slots.size()) * sizeof(vox::FloatCells::Cell);
  std::printf("  cell boxes: build %.1f ms, %.2f MB (the cell tables without them %.2f MB)\n", boxSeconds * 1e3,
              double(accel.cellBoxes.size() * sizeof(vox::CellBox)) / 1e6, tableBytes / 1e6);
  std::printf("  %-11s %10s %10s %12s %12s %8s %8s %9s %9s %9s %s\n", "set", "query", "embree", "ours", "ours/embree",
              "(best)", "(cpu)", "same", "close t", "mismatch", "brute force (diff/checked), per ray");
  for (const RaySet& set : sets) {
    if (oursOnly) {
      std::vector<vox::Hit> ours(set.rays.size());
      std::vector<Method> methods;
      methods.push_back({"ours", [&] { voxTrace(accel, set, ours); }});
      timeInTurns(methods, reps);
      std::printf("  %-11s ours %.3f Mrays/s (median), cpu %.3f\n", set.name.c_str(),
                  set.rays.size() / methods[0].median() / 1e6, set.rays.size() / methods[0].median(true) / 1e6);
      continue;
    }
    std::vector<EmbreeResult> e(set.rays.size());
    std::vector<vox::Hit> ours(set.rays.size());
    std::vector<Method> methods;
    methods.push_back({"embree", [&] { embreeTrace(embree.scene, set, e); }});
    methods.push_back({"ours", [&] { voxTrace(accel, set, ours); }});
    std::vector<vox::Hit> byIdHits(set.rays.size());
    methods.push_back({"ours double only", [&] { voxTrace(byId, set, byIdHits); }});
    std::vector<vox::Hit> packetHits(set.rays.size());
    methods.push_back({"ours packets", [&] { voxPackets(accel, set, packetHits); }});
    std::vector<vox::Hit> textbookHits(set.rays.size());
    methods.push_back({"textbook", [&] { textbookTrace(accel, set, textbookHits); }});
    std::vector<double> stopT(set.rays.size());  // where the walk alone stops: the nearest hit, as traceRay finds it
    for (size_t i = 0; i < set.rays.size(); ++i) stopT[i] = vox::traceRay(accel, set.rays[i]).t;
    std::atomic<uint64_t> sink{0};
    methods.push_back({"textbook walk alone", [&] { textbookWalk(accel, set, stopT, sink); }});
    std::vector<vox::Hit> uniformHits(set.rays.size());
    methods.push_back({"ours uniform", [&] { voxTrace(uniform, set, uniformHits); }});
    timeInTurns(methods, reps);
    const uint64_t uniformDiff = differingHits(ours, uniformHits);
    vox::TraceStats uniformStats;
    for (size_t i = 0; i < set.rays.size(); i += 97)
      set.occlusion ? void(vox::occluded(uniform, set.rays[i], &uniformStats))
                    : void(vox::traceRay(uniform, set.rays[i], &uniformStats));
    const uint64_t packetDiff = differingHits(ours, packetHits), byIdDiff = differingHits(ours, byIdHits);
    const uint64_t textbookDiff = differingHits(ours, textbookHits);
    const Agreement a = compareWithEmbree(set, ours, e, diag);
    uint64_t checked = 0;
    const uint64_t bruteDiff =
        bruteForceDifferences(brute, set, ours, std::max<size_t>(1, set.rays.size() / 500), checked);
    const double n = double(set.rays.size());
    vox::TraceStats st;
    for (size_t i = 0; i < set.rays.size(); i += 97)
      set.occlusion ? void(vox::occluded(accel, set.rays[i], &st)) : void(vox::traceRay(accel, set.rays[i], &st));
    std::printf(
        "  %-11s %10s %8.2f M %10.2f M %12.3f %8.3f %8.3f %8.3f%% %8.3f%% %9llu %llu/%llu  %.1f cells, %.1f tests "
        "(%.2f in double)"
        "  double only: %.3f (cpu %.3f), %llu differ  packets/embree: %.3f, %llu differ"
        "  textbook/embree: %.3f (walk alone %.3f), %llu differ  uniform/embree: %.3f (%.1f cells), %llu differ\n",
        set.name.c_str(), set.occlusion ? "occluded" : "closest", n / methods[0].median() / 1e6,
        n / methods[1].median() / 1e6, methods[0].median() / methods[1].median(), methods[0].best / methods[1].best,
        methods[0].median(true) / methods[1].median(true), 100.0 * a.same / n, 100.0 * a.closeT / n,
        (unsigned long long)a.mismatch, (unsigned long long)bruteDiff, (unsigned long long)checked,
        double(st.cells) / st.rays, double(st.tests + st.filtered) / st.rays, double(st.tests) / st.rays,
        methods[2].median() / methods[1].median(), methods[2].median(true) / methods[1].median(true),
        (unsigned long long)byIdDiff, methods[0].median() / methods[3].median(), (unsigned long long)packetDiff,
        methods[0].median() / methods[4].median(), methods[0].median() / methods[5].median(),
        (unsigned long long)textbookDiff, methods[0].median() / methods[6].median(),
        double(uniformStats.cells) / uniformStats.rays, (unsigned long long)uniformDiff);
    if (set.name == "ao")  // one ambient-occlusion ray per pixel of a 1024x1024 image at this set's rate
      std::printf("  cell boxes' build: %.2f%% of a 1024x1024 image of one ao ray per pixel (%.3f s at this rate)\n",
                  100 * boxSeconds / (1024.0 * 1024.0 / n * methods[1].median()),
                  1024.0 * 1024.0 / n * methods[1].median());
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  unsigned threads = 1;
  uint32_t size = 1024;
  int reps = 7;
  std::vector<double> factors;
  std::vector<std::string> scenes;
  bool incoherent = false, oursOnly = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc)
      threads = unsigned(std::atoi(argv[++i]));
    else if (a == "--size" && i + 1 < argc)
      size = uint32_t(std::atoi(argv[++i]));
    else if (a == "--reps" && i + 1 < argc)
      reps = std::max(1, std::atoi(argv[++i]));
    else if (a == "--factor" && i + 1 < argc)
      factors.push_back(std::atof(argv[++i]));
    else if (a == "--incoherent")
      incoherent = true;
    else if (a == "--ours-only")
      oursOnly = true;
    else if (a == "--help" || a == "-h") {
      std::printf(
          "bench_trace [SCENE...] [--threads N] [--size S] [--reps R] [--factor F]... [--incoherent [--ours-only]]\n"
          "  Rays per second of our grid walk against Embree 3 on the same rays (docs/trace.md, docs/speed.md).\n"
          "  Default scenes: the course's 40k bunny, the 69k Stanford bunny, SheenCloth (from VOX_SEED_DIR).\n"
          "  --threads N     TBB threads (default 1)\n"
          "  --size S        S x S primary rays (default 1024)\n"
          "  --reps R        rounds taken in turns (default 7)\n"
          "  --factor F      grids of F cells per triangle (repeatable; primary default 0.5 1 2 3, incoherent: the\n"
          "                  default grid of vox-voxelize)\n"
          "  --incoherent    secondary rays (reflection, hemisphere, ao, shadow) from the primary hits\n"
          "  --ours-only     with --incoherent: time only our walk, check nothing (for profiling)\n");
      return 0;
    } else if (a.rfind("--", 0) == 0) {
      std::fprintf(stderr, "bench_trace: unknown option %s (see --help)\n", a.c_str());
      return 1;
    } else
      scenes.push_back(a);
  }
  // Incoherent sets: the default grid unless factors are given.
  const std::vector<double> incoherentFactors = factors.empty() ? std::vector<double>{0} : factors;
  if (factors.empty()) factors = {0.5, 1, 2, 3};
  // The incoherent sets read SheenCloth from its glTF sample (issue 12), the primary table from its OBJ copy.
  const std::string cloth =
      incoherent ? "/gltf/SheenCloth/glTF/SheenCloth.gltf" : "/meshes/derived/sheencloth_115k.obj";
  if (scenes.empty())
    scenes = {std::string(VOX_SEED_DIR) + "/6837/scenes/bunny_40k.obj",
              std::string(VOX_SEED_DIR) + "/meshes/bun_zipper.ply", std::string(VOX_SEED_DIR) + cloth};
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  if (incoherent)
    std::printf(
        "threads: %u, secondary rays from the hits of %ux%u primary rays, Mrays/s of the median of %d rounds "
        "taken in turns (best: ratio of best times; cpu: of median process CPU times)\n",
        threads, size, size, reps);
  else
    std::printf("threads: %u, image: %ux%u primary rays, best of %d rounds taken in turns\n", threads, size, size,
                reps);

  for (const std::string& path : scenes) try {
      if (incoherent)
        for (double f : incoherentFactors) benchIncoherent(path, threads, size, reps, oursOnly, f);
      else
        benchPrimary(path, threads, size, reps, factors);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_trace: %s\n", e.what());
      return 2;
    }
  return 0;
}
