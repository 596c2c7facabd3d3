#include "options.h"

#include "../common/cli_app.h"

#include <cmath>
#include <cstdlib>

#include "vox/core/error.h"
#include "vox/io/atomic_file.h"
#include "vox/io/image_io.h"

namespace vox::trace_tool {
namespace {

constexpr uint32_t kMaxSide = 16384;
constexpr uint64_t kMaxPixels = uint64_t(1) << 28;
constexpr uint32_t kMaxSamples = 4096;
// A hit may spawn a reflected and a refracted ray, so a sample traces up to 2^(bounces + 1) rays when no path
// weight falls under --weight (perfect mirrors and glass): 10 bounces bound that at 2047 per sample, well past
// the course's 5.
constexpr uint32_t kMaxBounces = 10;

Vec3 vec(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

void checkSize(const RenderOptions& ro) {
  if (ro.width == 0 || ro.height == 0 || ro.width > kMaxSide || ro.height > kMaxSide ||
      uint64_t(ro.width) * ro.height > kMaxPixels)
    fail<UsageError>("--size ", ro.width, " ", ro.height, ": each side must be 1..", kMaxSide,
                     " and at most 2^28 pixels");
}

}  // namespace

void addOptions(CLI::App& app, Options& opt) {
  app.add_option("grid", opt.grid, "Input grid file (.vgrid, from vox-voxelize)")->required();
  app.add_option("-o,--output", opt.output, "Output image; format from the extension (.png .tga .exr .jpg .tif ...)")
      ->required();
  app.add_option("--size", opt.size, "Image size W H (default 512 512)")->expected(2);
  app.add_option("--mode", opt.mode,
                 "shade (materials, lights, shadows), voxels (occupied cells as cubes coloured by primitive count), "
                 "count (heat map of cells visited per pixel), normals ((n+1)/2 of the normal facing the viewer), "
                 "depth (distance along the unit ray; float in EXR/TIFF, grey near-bright otherwise)");
  app.add_option("--accel", opt.accel,
                 "grid (walk the grid, jumping over empty boxes), uniform (step through every cell) or none (test "
                 "every primitive)");
  app.add_option("--samples", opt.samples, "Jittered samples per pixel (stratified when a square number)");
  app.add_option("--bounces", opt.bounces, "Shade mode: reflection and refraction depth (default 0, the course's)");
  app.add_option("--weight", opt.weight, "Shade mode: stop a path whose contribution falls under W (default 0.01)");
  app.add_flag("--shade-back", opt.shadeBack, "Shade mode: light back faces too (without it they are black)");
  app.add_flag("--no-shadows", opt.noShadows, "Shade mode: no shadow rays (the course's lines without -shadows)");
  app.add_option("--filter", opt.filter, "Reconstruction filter KIND RADIUS: box, tent or gaussian, radius in pixels")
      ->expected(2);
  app.add_flag("--stats", opt.stats, "Print statistics (name: value) on stderr");
  auto* eye =
      app.add_option("--eye", opt.eye, "Camera position X Y Z (with --look-at: a perspective camera)")->expected(3);
  auto* look = app.add_option("--look-at", opt.lookAt, "Point the camera looks at X Y Z")->expected(3);
  eye->needs(look);
  look->needs(eye);
  app.add_option("--up", opt.up, "Camera up vector X Y Z")->expected(3);
  app.add_option("--fov", opt.fov, "Vertical field of view in degrees (makes the camera perspective)");
  cli::addCommonOptions(app, opt.common);
  app.footer("Exit codes: 0 ok, 1 usage, 2 bad input, 3 cannot write.");
}

RenderOptions renderOptions(const Options& opt) {
  RenderOptions ro;
  ro.mode = parseRenderMode(opt.mode);
  if (!opt.size.empty()) {
    ro.width = opt.size[0];
    ro.height = opt.size[1];
  }
  checkSize(ro);
  if (opt.samples == 0 || opt.samples > kMaxSamples) fail<UsageError>("--samples must be 1..", kMaxSamples);
  if (opt.fov != 0 && !(opt.fov > 0 && opt.fov < 180)) fail<UsageError>("--fov must be between 0 and 180 degrees");
  if (!imageFormatSupported(opt.output))
    fail<UsageError>(opt.output, ": unknown image format (use an extension such as .png, .tga, .exr, .jpg)");
  checkOutputPath(opt.output, {opt.grid});
  ro.samples = opt.samples;
  ro.bounces = opt.bounces;
  ro.weight = opt.weight;
  ro.shadeBack = opt.shadeBack;
  ro.shadows = !opt.noShadows;
  if (!(std::isfinite(opt.weight) && opt.weight >= 0)) fail<UsageError>("--weight must be a finite number >= 0");
  if (opt.bounces > kMaxBounces) fail<UsageError>("--bounces must be 0..", kMaxBounces);
  if (!opt.filter.empty()) {
    ro.filter = parseFilter(opt.filter[0]);
    char* end = nullptr;
    ro.filterRadius = std::strtod(opt.filter[1].c_str(), &end);
    if (end == opt.filter[1].c_str() || *end != 0 || !(ro.filterRadius > 0 && ro.filterRadius <= kMaxFilterRadius))
      fail<UsageError>("--filter ", opt.filter[0], " '", opt.filter[1], "': the radius must be a number in (0, ",
                       kMaxFilterRadius, "] pixels");
  }
  return ro;
}

Camera resolveCamera(const Options& opt, const GridFile& file) {
  Camera cam = file.scene.camera ? *file.scene.camera : defaultCamera(file.grid.bounds);
  if (!opt.eye.empty()) {
    const Camera scene = cam;
    cam = Camera{};
    cam.kind = CameraKind::Perspective;
    cam.center = vec(opt.eye);
    cam.direction = vec(opt.lookAt) - vec(opt.eye);
    cam.up = scene.up;
    cam.fovDegrees = scene.kind == CameraKind::Perspective ? scene.fovDegrees : 45;
    // The scene's angle keeps the side it spans, so that moving the eye keeps the framing's width.
    if (scene.kind == CameraKind::Perspective) cam.span = scene.span;
    if (!isFinite(cam.center) || !isFinite(vec(opt.lookAt))) fail<UsageError>("--eye and --look-at must be finite");
    if (!(length(cam.direction) > 0)) fail<UsageError>("--eye and --look-at must differ");
  }
  if (!opt.up.empty()) cam.up = vec(opt.up);
  if (opt.fov != 0) {
    cam.kind = CameraKind::Perspective;
    cam.fovDegrees = opt.fov;
    cam.span = CameraSpan::Height;  // --fov is vertical (DESIGN.md), whatever the scene's camera spans
  }
  return cam;
}

std::optional<int> parseCommandLine(int argc, char** argv, Options& opt) {
  CLI::App app{"Render an image from a grid file (.vgrid) by marching rays through the grid.", "vox-trace"};
  addOptions(app, opt);
  return cli::parse(app, argc, argv);
}

}  // namespace vox::trace_tool
