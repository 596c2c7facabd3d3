// Rendering an image by tracing rays through an Accel (DESIGN.md "vox-trace"). No file I/O here (image_io.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "vox/core/image.h"
#include "vox/core/scene.h"
#include "vox/trace/accel.h"
#include "vox/trace/ray.h"
#include "vox/trace/traverse.h"

namespace vox {

enum class RenderMode : uint8_t { Shade, Voxels, Count, Normals, Depth };
// Throws UsageError for a name other than shade, voxels, count, normals, depth.
RenderMode parseRenderMode(const std::string& name);

// Reconstruction filters of the course's assignment 7: a pixel is the weighted mean of the samples (its own and
// its neighbours') within the filter's support around its centre; d is the distance in pixels, r the radius.
// Box: weight 1 where |dx| < r and |dy| < r; Tent: max(0, 1 - d / r); Gaussian: exp(-d^2 / (2 r^2)) for d < 2r.
enum class FilterKind : uint8_t { None, Box, Tent, Gaussian };
// Throws UsageError for a name other than box, tent, gaussian.
FilterKind parseFilter(const std::string& name);
// Largest filter radius, in pixels: the filter visits (2 ceil(2r) + 1)^2 pixels' samples per pixel.
inline constexpr double kMaxFilterRadius = 16;

struct RenderOptions {
  uint32_t width = 512, height = 512;
  RenderMode mode = RenderMode::Shade;
  uint32_t samples = 1;  // per pixel; > 1 jitters inside the pixel (stratified when a square number)
  // Shade mode, the course's recursive ray tracing (docs/trace.md "Shading"): reflected and refracted rays up to
  // `bounces` deep, a path stopped when its weight (product of the reflective or transparent colours' largest
  // component along it) falls under `weight`; back faces black unless `shadeBack`; shadow rays unless !shadows.
  uint32_t bounces = 0;
  double weight = 0.01;
  bool shadeBack = false;
  bool shadows = true;
  FilterKind filter = FilterKind::None;  // None: each pixel is the plain mean of its own samples
  double filterRadius = 0.5;             // pixels
  Camera camera;                         // already resolved (scene camera, overrides or defaultCamera)
  uint64_t seed = 0;                     // of the per-pixel jitter
  // Called from worker threads after each block of 8x8 pixels with the fraction of pixels done; may be empty. May
  // throw to cancel (the exception leaves traceImage).
  std::function<void(double)> progress;
};

struct RenderStats {
  TraceStats trace;  // every ray: primary, shadow
  double traceSeconds = 0;
  double countMax = 0;                // count mode: cells visited of the busiest pixel (the top of the heat map)
  double depthMin = 0, depthMax = 0;  // depth mode: range over hit pixels (0, 0 when nothing is hit)
};

// The primary ray through image position (px, py), in pixels from the top-left corner (pixel centres at +0.5),
// by the camera convention of DESIGN.md: right = normalize(direction x up), trueUp = right x direction,
// perspective rays from the centre through direction + u right + v trueUp (u, v from the vertical fov, v up),
// orthographic rays parallel to direction from centre + u right + v trueUp (u, v from orthoHeight). A camera with
// CameraSpan::LongerSide (the course's) spreads its fov or orthoHeight over the width instead when width > height.
// The direction of a perspective ray is not normalised. Throws UsageError for a degenerate camera.
Ray primaryRay(const Camera& camera, uint32_t width, uint32_t height, double px, double py);

// Renders `scene` (the scene of accel.grid) in options.mode. Output channels: shade, voxels, count, normals: RGB in
// [0, 1] (linear, unclamped for shade); depth: one channel, the distance along the unit ray direction to the hit,
// 0 where nothing is hit. Without lights the scene is lit by a headlight (a directional light along the camera
// direction, casting no shadow). Throws UsageError for a zero size or sample count, a negative or non-finite
// weight or filter radius; LimitError when the samples kept for a filter exceed the memory budget.
Image traceImage(const Scene& scene, const Accel& accel, const RenderOptions& options, RenderStats* stats = nullptr);

// The depth image as grey for 8-bit formats, linear in 1/depth: the nearest hit 1, the farthest 0.15, nothing hit 0.
Image depthToGrey(const Image& depth);

}  // namespace vox
