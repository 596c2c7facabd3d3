#include "vox/trace/render.h"

#include <tbb/blocked_range2d.h>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "trace/pixel_filter.h"
#include "trace/shade.h"
#include "vox/core/colormap.h"
#include "vox/core/error.h"
#include "vox/trace/trace_packet.h"

namespace vox {

RenderMode parseRenderMode(const std::string& name) {
  if (name == "shade") return RenderMode::Shade;
  if (name == "voxels") return RenderMode::Voxels;
  if (name == "count") return RenderMode::Count;
  if (name == "normals") return RenderMode::Normals;
  if (name == "depth") return RenderMode::Depth;
  fail<UsageError>("unknown mode '", name, "' (expected shade, voxels, count, normals or depth)");
}

namespace {

// The colour of a cell by its primitive count: vox-export --color count's, so a cell looks alike in both.
Vec3 voxelColor(uint32_t count, uint32_t maxCount) { return countColor(count, maxCount); }

struct Frame {
  Vec3 dir, right, up;
  double halfHeight = 1;  // half the span of the image plane at distance 1 (perspective) or in world units (ortho)
};

Frame cameraFrame(const Camera& c) {
  Frame f;
  f.dir = normalize(c.direction);
  f.right = normalize(cross(f.dir, c.up));
  f.up = cross(f.right, f.dir);
  if (!isFinite(f.dir) || !isFinite(f.right) || length(f.dir) == 0 || length(f.right) == 0)
    fail<UsageError>("camera direction and up must be finite, non-zero and not parallel");
  f.halfHeight = c.kind == CameraKind::Perspective ? std::tan(c.fovDegrees * M_PI / 360.0) : 0.5 * c.orthoHeight;
  return f;
}

Ray rayFromFrame(const Camera& camera, const Frame& f, uint32_t width, uint32_t height, double px, double py) {
  // The camera's angle or size spans the height, or for the course's cameras the longer side: across a wide image
  // it spans the width and the height gets height / width of it. Factors of exactly 1 keep the products of square
  // images and of CameraSpan::Height bit for bit what they were.
  const bool acrossWidth = camera.span == CameraSpan::LongerSide && width > height;
  const double across = acrossWidth ? 1.0 : double(width) / double(height);
  const double upward = acrossWidth ? double(height) / double(width) : 1.0;
  const double sx = 2 * px / width - 1;
  const double sy = 1 - 2 * py / height;
  Ray ray;
  const double h = f.halfHeight;
  if (camera.kind == CameraKind::Perspective) {
    ray.origin = camera.center;
    ray.direction = f.dir + f.right * (sx * h * across) + f.up * (sy * h * upward);
  } else {
    ray.origin = camera.center + f.right * (sx * h * across) + f.up * (sy * h * upward);
    ray.direction = f.dir;
  }
  return ray;
}

uint64_t splitMix(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
double uniform(uint64_t& state) { return double(splitMix(state) >> 11) * 0x1.0p-53; }

// The lights of the shade mode: the scene's, or a headlight (which casts no shadow: its shadows hide behind what
// casts them).
void setLights(Shader& shader, const Scene& scene, const Frame& frame) {
  shader.lights = scene.lights;
  if (shader.lights.empty()) {
    Light head;
    head.kind = LightKind::Directional;
    head.direction = frame.dir;
    shader.lights.push_back(head);
    shader.castShadows = false;
  }
}

struct Renderer {
  const Scene& scene;
  const Accel& accel;
  const RenderOptions& options;
  Frame frame;
  Shader shader;
  uint32_t maxCellPrims = 1;
  uint32_t strata = 1;  // round(sqrt(samples)): samples are stratified when its square is the sample count

  // The shade mode for a packet of primary rays and their hits: the shadow rays of each light are traced as packets
  // too (they start near each other and end at one light, or run parallel); reflected and refracted rays, and the
  // shadow rays where they land, are traced one by one (Shader::secondary). Writes RGB for each ray into out.
  void shadePacket(std::span<const Ray> rays, std::span<const Hit> hits, float (*out)[3], TraceStats& st) const {
    const size_t lightCount = shader.lights.size();
    std::vector<Surface> surfaces(rays.size());
    for (size_t r = 0; r < rays.size(); ++r)
      if (hits[r].valid()) surfaces[r] = shader.surface(rays[r], hits[r]);
    // First pass: collect the shadow rays, per light, with the slot of their answer (ray * lightCount + light). It
    // runs the shading itself, so that the rays asked for are exactly those the second pass will ask about.
    std::vector<std::vector<Ray>> shadowRays(lightCount);
    std::vector<std::vector<uint32_t>> slots(lightCount);
    std::vector<uint8_t> seen(rays.size() * lightCount, 1);
    for (size_t r = 0; r < rays.size() && shader.castShadows; ++r) {
      if (!hits[r].valid()) continue;
      shader.local(rays[r], surfaces[r], [&](size_t li, const Ray& shadow) {
        shadowRays[li].push_back(shadow);
        slots[li].push_back(uint32_t(r * lightCount + li));
        return true;
      });
    }
    bool blocked[kMaxPacketRays];
    for (size_t li = 0; li < lightCount; ++li)
      for (size_t begin = 0; begin < shadowRays[li].size(); begin += kMaxPacketRays) {
        const size_t count = std::min<size_t>(kMaxPacketRays, shadowRays[li].size() - begin);
        occludedPacket(accel, std::span(shadowRays[li]).subspan(begin, count), {blocked, count}, &st);
        for (size_t i = 0; i < count; ++i) seen[slots[li][begin + i]] = !blocked[i];
      }
    // Second pass: shade with the answers, then add what the surface reflects and transmits.
    for (size_t r = 0; r < rays.size(); ++r) {
      const auto answer = [&](size_t li, const Ray&) { return seen[r * lightCount + li] != 0; };
      Vec3 c = scene.background;
      if (hits[r].valid())
        c = shader.local(rays[r], surfaces[r], answer) + shader.secondary(rays[r], surfaces[r], 0, 1.0, st);
      out[r][0] = float(c.x), out[r][1] = float(c.y), out[r][2] = float(c.z);
    }
  }

  Vec3 shadeVoxel(const Ray& ray, const CellHit& cell) const {
    Vec3 n;
    if (cell.entryAxis >= 0) {
      n.at(cell.entryAxis) = ray.direction[cell.entryAxis] > 0 ? -1 : 1;
    } else {
      n = normalize(-ray.direction);
    }
    const Vec3 base = cell.solid ? Vec3{0.6, 0.6, 0.6} : voxelColor(cell.primCount, maxCellPrims);
    Vec3 color = mul(scene.ambient, base);
    const Vec3 p = ray.origin + ray.direction * cell.t;
    for (const Light& light : shader.lights) {
      const LightSample ls = sampleLight(light, p);
      const double nl = dot(n, ls.toLight);
      if (nl > 0) color = color + mul(base * nl, ls.color);
    }
    return color;
  }

  // Modes whose samples are the nearest hit of the primary ray: those are traced in packets.
  bool nearestHitMode() const {
    return options.mode == RenderMode::Shade || options.mode == RenderMode::Normals ||
           options.mode == RenderMode::Depth;
  }

  // One sample of the normals or depth mode from its hit; writes `channels` values into out.
  void fromHit(const Ray& ray, const Hit& hit, float* out) const {
    switch (options.mode) {
      case RenderMode::Normals: {
        Vec3 c;
        if (hit.valid()) {
          Vec3 n = hitNormal(accel, ray, hit);
          if (dot(n, ray.direction) > 0) n = -n;
          c = (n + Vec3{1, 1, 1}) * 0.5;
        }
        out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
        break;
      }
      case RenderMode::Depth:
        out[0] = hit.valid() ? float(hit.t * length(ray.direction)) : 0.0f;
        break;
      default:
        break;
    }
  }

  // Blocks of kBlock x kBlock pixels: each sample index of a block is one packet of primary rays.
  static constexpr uint32_t kBlock = 8;
  static_assert(kBlock * kBlock <= kMaxPacketRays);

  // Where sample s of pixel (x, y) lies: the centre for one sample, else jittered in its stratum of a sqrt(samples)
  // square grid, or anywhere in the pixel when the count is not a square.
  void samplePosition(uint32_t x, uint32_t y, uint32_t s, uint64_t& rng, double& sx, double& sy) const {
    sx = x + 0.5, sy = y + 0.5;
    if (options.samples <= 1) return;
    if (strata * strata == options.samples) {
      sx = x + ((s % strata) + uniform(rng)) / strata;
      sy = y + ((s / strata) + uniform(rng)) / strata;
    } else {
      sx = x + uniform(rng);
      sy = y + uniform(rng);
    }
  }

  // The samples of one packet (primary rays `rays`, one per pixel of a block) in the image's channels.
  void shadeSamples(std::span<const Ray> rays, float (*value)[3], TraceStats& st) const {
    const uint32_t count = uint32_t(rays.size());
    if (nearestHitMode()) {
      Hit hits[kMaxPacketRays];
      tracePacket(accel, rays, {hits, count}, &st);
      if (options.mode == RenderMode::Shade)
        shadePacket(rays, {hits, count}, value, st);
      else
        for (uint32_t p = 0; p < count; ++p) fromHit(rays[p], hits[p], value[p]);
    } else {
      for (uint32_t p = 0; p < count; ++p) walkSample(rays[p], value[p], st);
    }
  }

  // Pixels [x0, x1) x [y0, y1) (at most kBlock a side): every sample, the average into `image`, and each sample
  // into `store` when a reconstruction filter will make the image instead.
  void renderBlock(uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1, Image& image, SampleStore& store,
                   TraceStats& st) const {
    uint32_t px[kMaxPacketRays], py[kMaxPacketRays], count = 0;
    uint64_t rng[kMaxPacketRays];
    for (uint32_t y = y0; y < y1; ++y)
      for (uint32_t x = x0; x < x1; ++x) {
        px[count] = x, py[count] = y;
        rng[count++] = options.seed ^ ((uint64_t(y) << 32) | x) * 0x9e3779b97f4a7c15ull;
      }
    float sum[kMaxPacketRays][3] = {};
    Ray rays[kMaxPacketRays];
    for (uint32_t s = 0; s < options.samples; ++s) {
      double jx[kMaxPacketRays], jy[kMaxPacketRays];
      for (uint32_t p = 0; p < count; ++p) {
        double sx, sy;
        samplePosition(px[p], py[p], s, rng[p], sx, sy);
        rays[p] = rayFromFrame(options.camera, frame, image.width, image.height, sx, sy);
        jx[p] = sx - px[p], jy[p] = sy - py[p];
      }
      float value[kMaxPacketRays][3];
      shadeSamples({rays, count}, value, st);
      for (uint32_t p = 0; p < count; ++p)
        for (uint32_t c = 0; c < image.channels; ++c) sum[p][c] += value[p][c];
      if (store.active())
        for (uint32_t p = 0; p < count; ++p) store.put(px[p], py[p], s, jx[p], jy[p], value[p]);
    }
    for (uint32_t p = 0; p < count; ++p) {
      float* out = image.at(px[p], py[p]);
      for (uint32_t c = 0; c < image.channels; ++c) out[c] = sum[p][c] / float(options.samples);
    }
  }

  // One sample of the voxels or count mode.
  void walkSample(const Ray& ray, float* out, TraceStats& st) const {
    if (options.mode == RenderMode::Voxels) {
      const CellHit cell = firstOccupiedCell(accel, ray, &st);
      const Vec3 c = cell.hit ? shadeVoxel(ray, cell) : scene.background;
      out[0] = float(c.x), out[1] = float(c.y), out[2] = float(c.z);
    } else {
      const uint64_t before = st.cells;
      traceRay(accel, ray, &st);
      out[0] = float(st.cells - before);
    }
  }
};

// The count mode's cells per pixel as a heat map (the largest count in `maxCount`).
Image countToHeat(const Image& counts, float& maxCount) {
  maxCount = 0;
  for (float v : counts.pixels) maxCount = std::max(maxCount, v);
  Image heat;
  heat.width = counts.width;
  heat.height = counts.height;
  heat.channels = 3;
  heat.pixels.resize(uint64_t(counts.width) * counts.height * 3);
  for (uint64_t i = 0; i < uint64_t(counts.width) * counts.height; ++i) {
    const Vec3 c = heatColor(counts.pixels[i], maxCount);
    heat.pixels[3 * i] = float(c.x), heat.pixels[3 * i + 1] = float(c.y), heat.pixels[3 * i + 2] = float(c.z);
  }
  return heat;
}

// The smallest and largest depth of the pixels that hit something (depth > 0); both stay as they are when none did.
void depthRange(const Image& depth, double& lo, double& hi) {
  bool any = false;
  for (float v : depth.pixels) {
    if (v <= 0) continue;
    lo = any ? std::min(lo, double(v)) : v;
    hi = any ? std::max(hi, double(v)) : v;
    any = true;
  }
}

}  // namespace

Ray primaryRay(const Camera& camera, uint32_t width, uint32_t height, double px, double py) {
  return rayFromFrame(camera, cameraFrame(camera), width, height, px, py);
}

Image traceImage(const Scene& scene, const Accel& accel, const RenderOptions& options, RenderStats* stats) {
  if (options.width == 0 || options.height == 0) fail<UsageError>("image size must be at least 1x1");
  if (options.samples == 0) fail<UsageError>("samples must be at least 1");
  if (!std::isfinite(options.weight) || options.weight < 0) fail<UsageError>("weight must be a finite number >= 0");
  if (options.filter != FilterKind::None && !(options.filterRadius > 0 && options.filterRadius <= kMaxFilterRadius))
    fail<UsageError>("filter radius must be in (0, ", kMaxFilterRadius, "] pixels");
  if (scene.materials.empty()) fail<InputError>("scene has no material");
  Renderer r{scene, accel, options, cameraFrame(options.camera), Shader{scene, accel, options, {}, true, 1}, 1};
  setLights(r.shader, scene, r.frame);
  r.shader.castShadows = r.shader.castShadows && options.shadows;
  const Box& b = accel.grid->bounds;
  r.shader.sceneSize = std::max(length(b.hi - b.lo), 1e-300);
  for (size_t c = 0; c < accel.grid->occupiedCount(); ++c)
    r.maxCellPrims = std::max<uint32_t>(r.maxCellPrims, uint32_t(accel.grid->cellPrims(c).size()));
  r.strata = uint32_t(std::lround(std::sqrt(double(options.samples))));

  Image image;
  image.width = options.width;
  image.height = options.height;
  const bool single = options.mode == RenderMode::Count || options.mode == RenderMode::Depth;
  image.channels = single ? 1 : 3;
  image.pixels.assign(uint64_t(image.width) * image.height * image.channels, 0.0f);

  SampleStore store;
  if (options.filter != FilterKind::None)
    store = makeSampleStore(image.width, image.height, options.samples, image.channels);
  tbb::combinable<TraceStats> perThread;
  std::atomic<uint64_t> pixelsDone{0};
  const double pixels = double(image.width) * double(image.height);
  const auto start = std::chrono::steady_clock::now();
  constexpr uint32_t kTile = 16;
  tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, image.height, kTile, 0, image.width, kTile),
                    [&](const tbb::blocked_range2d<uint32_t>& tile) {
                      TraceStats& st = perThread.local();
                      const auto rows = tile.rows(), cols = tile.cols();
                      for (uint32_t by = rows.begin(); by < rows.end(); by += Renderer::kBlock) {
                        const uint32_t byEnd = std::min(by + Renderer::kBlock, rows.end());
                        for (uint32_t bx = cols.begin(); bx < cols.end(); bx += Renderer::kBlock) {
                          const uint32_t bxEnd = std::min(bx + Renderer::kBlock, cols.end());
                          r.renderBlock(bx, bxEnd, by, byEnd, image, store, st);
                          // After every block, not every band of the image's rows: a caller that cancels by
                          // throwing from progress (the Python module on Ctrl-C) waits for one block (issue 24).
                          if (options.progress) {
                            const uint64_t done = uint64_t(byEnd - by) * (bxEnd - bx);
                            options.progress(double(pixelsDone.fetch_add(done) + done) / pixels);
                          }
                        }
                      }
                    });
  if (store.active()) image = filterSamples(store, options.filter, options.filterRadius);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  RenderStats rs;
  perThread.combine_each([&](const TraceStats& s) { rs.trace += s; });
  rs.traceSeconds = seconds;
  if (options.mode == RenderMode::Count) {
    float maxCount = 0;
    image = countToHeat(image, maxCount);
    rs.countMax = maxCount;
  } else if (options.mode == RenderMode::Depth) {
    depthRange(image, rs.depthMin, rs.depthMax);
  }
  if (stats) *stats = rs;
  return image;
}

Image depthToGrey(const Image& depth) {
  Image grey = depth;
  double lo = 0, hi = 0;  // float values, exactly
  depthRange(depth, lo, hi);
  for (float& v : grey.pixels) {
    if (v <= 0) continue;
    // Linear in inverse depth, so that a floor running to the horizon does not wash out everything near.
    const double f = hi > lo ? (1.0 / v - 1.0 / hi) / (1.0 / lo - 1.0 / hi) : 1.0;
    v = float(0.15 + 0.85 * f);
  }
  return grey;
}

}  // namespace vox
