// libvox.render and libvox.save_image: vox-trace's image as a numpy array, and its image writer.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "binding.h"
#include "vox/core/exact_number.h"
#include "vox/core/error.h"
#include "vox/io/image_io.h"
#include "vox/io/input_file.h"
#include "vox/trace/render.h"

namespace voxpy {

namespace {

// vox-trace's limits (tools/trace/main.cpp): what one image may ask for.
constexpr uint32_t kMaxSide = 16384;
constexpr uint64_t kMaxPixels = uint64_t(1) << 28;
constexpr uint32_t kMaxSamples = 4096;
constexpr uint32_t kMaxBounces = 10;

// A direction of any finite size scaled to one a length can be taken of: normalize() squares the components, so
// 1e-300 underflows to a zero length and 1e300 overflows to infinity. Directions of ordinary size are kept as they
// are (the camera is then vox-trace's, bit for bit).
vox::Vec3 measurable(vox::Vec3 d) {
  const double len = vox::length(d);
  if (len > 0 && std::isfinite(len)) return d;
  const double largest = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  return largest > 0 ? d / largest : d;
}

// The scene's camera (or one framing the grid) with vox-trace's overrides --eye/--look-at, --up, --fov applied, in
// the same way (tools/trace/main.cpp, resolveCamera); UsageError naming the argument for a camera they cannot make.
vox::Camera resolveCamera(const PyGrid& g, const py::object& eye, const py::object& lookAt, const py::object& up,
                          const py::object& fov) {
  using namespace vox;
  Camera cam = g.scene().camera ? *g.scene().camera : defaultCamera(g.grid().bounds);
  if (eye.is_none() != lookAt.is_none()) fail<UsageError>("eye and look_at go together");
  if (!eye.is_none()) {
    const Vec3 e = vec3Arg(eye, "eye"), l = vec3Arg(lookAt, "look_at");
    const Camera scene = cam;
    cam = Camera{};
    cam.kind = CameraKind::Perspective;
    cam.center = e;
    cam.direction = l - e;
    // Halved, the difference of two finite doubles cannot overflow.
    if (!isFinite(cam.direction)) cam.direction = l * 0.5 - e * 0.5;
    if (cam.direction.x == 0 && cam.direction.y == 0 && cam.direction.z == 0)
      fail<UsageError>("eye and look_at must differ (both are ", e.x, ", ", e.y, ", ", e.z, ")");
    cam.direction = measurable(cam.direction);
    cam.up = scene.up;
    cam.fovDegrees = scene.kind == CameraKind::Perspective ? scene.fovDegrees : 45;
    // The scene's angle keeps the side it spans, so that moving the eye keeps the framing's width.
    if (scene.kind == CameraKind::Perspective) cam.span = scene.span;
  }
  if (!up.is_none()) {
    cam.up = vec3Arg(up, "up");
    if (cam.up.x == 0 && cam.up.y == 0 && cam.up.z == 0) fail<UsageError>("up must not be zero");
    cam.up = measurable(cam.up);
    if (!(length(cross(normalize(measurable(cam.direction)), cam.up)) > 0))
      fail<UsageError>("up is parallel to the view direction",
                       eye.is_none() ? " (the scene camera's)" : " (eye to look_at)");
  }
  if (!fov.is_none()) {
    const double f = floatArg(fov, "fov");
    if (!(f > 0 && f < 180)) fail<UsageError>("fov must be between 0 and 180 degrees, got ", vox::exactNumber(f));
    cam.kind = CameraKind::Perspective;
    cam.fovDegrees = f;
    cam.span = CameraSpan::Height;  // fov is vertical, whatever the scene's camera spans
  }
  // What is left to go wrong (the scene's up parallel to the new direction) is still the caller's choice of options.
  try {
    validateCamera(cam, "camera of eye, look_at, up, fov");
  } catch (const InputError& e) {
    throw UsageError(e.what());
  }
  return cam;
}

// vox-trace's options from render's arguments (all but the camera), each checked and named.
vox::RenderOptions renderOptions(const py::object& size, const py::object& mode, const py::object& samples,
                                 const py::object& bounces, const py::object& weight, const py::object& shadeBack,
                                 const py::object& shadows, const py::object& filter) {
  using namespace vox;
  RenderOptions ro;
  ro.mode = enumArg(mode, "mode", parseRenderMode);
  const auto wh = sequenceArg(size, "size", 2, "(width, height)");
  ro.width = uint32_t(intArg(wh[0], "size: width", 1, kMaxSide));
  ro.height = uint32_t(intArg(wh[1], "size: height", 1, kMaxSide));
  if (uint64_t(ro.width) * ro.height > kMaxPixels) fail<UsageError>("size: at most 2^28 pixels");
  ro.samples = uint32_t(intArg(samples, "samples", 1, kMaxSamples));
  ro.bounces = uint32_t(intArg(bounces, "bounces", 0, kMaxBounces));
  ro.weight = floatArg(weight, "weight");
  if (!(ro.weight >= 0)) fail<UsageError>("weight must be a finite number >= 0, got ", vox::exactNumber(ro.weight));
  ro.shadeBack = boolArg(shadeBack, "shade_back");
  ro.shadows = boolArg(shadows, "shadows");
  if (!filter.is_none()) {
    const auto f = sequenceArg(filter, "filter", 2, "(kind, radius): ('box' | 'tent' | 'gaussian', pixels)");
    ro.filter = enumArg(f[0], "filter kind", parseFilter);
    ro.filterRadius = floatArg(f[1], "filter radius");
    if (!(ro.filterRadius > 0 && ro.filterRadius <= kMaxFilterRadius))
      fail<UsageError>("filter radius must be in (0, ", kMaxFilterRadius, "] pixels, got ",
                       vox::exactNumber(ro.filterRadius));
  }
  return ro;
}

py::array_t<float> render(PyGrid& self, const py::object& size, const py::object& mode, const py::object& samples,
                          const py::object& bounces, const py::object& weight, const py::object& shadeBack,
                          const py::object& shadows, const py::object& filter, const py::object& eye,
                          const py::object& lookAt, const py::object& up, const py::object& fov,
                          const py::object& accelName, const py::object& threads, const py::object& progress) {
  using namespace vox;
  RenderOptions ro = renderOptions(size, mode, samples, bounces, weight, shadeBack, shadows, filter);
  const AccelKind accelKind = enumArg(accelName, "accel", parseAccel);
  ro.camera = resolveCamera(self, eye, lookAt, up, fov);
  const auto nThreads = threadsArg(threads);
  const bool single = ro.mode == RenderMode::Count || ro.mode == RenderMode::Depth;
  checkMemory(double(ro.width) * ro.height * (single ? 1 : 3) * sizeof(float), self.source(), "the image");

  Interrupt interrupt(progressCallable(progress, "tracing"));
  ro.progress = [&](double f) {
    if (!interrupt.poll(f)) fail<Error>("render cancelled");  // TBB cancels the other tiles and rethrows here
  };
  Image image = runLong(interrupt, nThreads, [&] {
    if (accelKind == AccelKind::Grid) return traceImage(self.scene(), self.accel(), ro);
    const Accel other = buildAccel(self.scene(), self.grid(), accelKind);  // "uniform" or "none"
    return traceImage(self.scene(), other, ro);
  });
  std::vector<py::ssize_t> shape{py::ssize_t(image.height), py::ssize_t(image.width)};
  if (image.channels != 1) shape.push_back(py::ssize_t(image.channels));
  return adoptVector<float>(std::move(image.pixels), shape);
}

std::string shapeText(const py::array& a) {
  std::ostringstream out;
  out << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) out << (d ? ", " : "") << a.shape(d);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

void saveImage(const py::object& pathObj, const py::handle& pixels) {
  const std::string path = pathArg(pathObj, "path");
  const py::array raw = asArray(pixels, "image");
  const char kind = raw.dtype().kind();
  if (!((kind == 'f' && raw.dtype().itemsize() <= 8) || kind == 'i' || kind == 'u'))
    failType("image must hold numbers (floats or integers), not ", std::string(py::str(raw.dtype())));
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(raw);
  const bool depth = a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1);
  if (!(depth || (a.ndim() == 3 && a.shape(2) == 3)) || a.shape(0) == 0 || a.shape(1) == 0)
    vox::fail<vox::InputError>("image: expected shape (H, W, 3) or (H, W) with H and W at least 1, got shape ",
                               shapeText(a));
  if (a.shape(0) > kMaxSide || a.shape(1) > kMaxSide)
    vox::fail<vox::InputError>("image: at most ", kMaxSide, " pixels a side, got shape ", shapeText(a));
  if (!vox::imageFormatSupported(path))
    vox::fail<vox::UsageError>("path: ", path,
                               ": unknown image format (use an extension such as .png, .tga, .exr, .jpg)");
  vox::Image image;
  image.height = uint32_t(a.shape(0));
  image.width = uint32_t(a.shape(1));
  image.channels = depth ? 1 : 3;
  image.pixels.assign(a.data(), a.data() + a.size());
  py::gil_scoped_release release;
  if (depth && !vox::imageFormatHoldsFloat(path)) image = vox::depthToGrey(image);
  vox::writeImage(path, image);
}

}  // namespace

void bindRender(py::module_& m) {
  m.def("render", &render, py::arg("grid"), py::arg("size") = py::make_tuple(512, 512), py::arg("mode") = "shade",
        py::kw_only(), py::arg("samples") = 1, py::arg("bounces") = 0, py::arg("weight") = 0.01,
        py::arg("shade_back") = false, py::arg("shadows") = true, py::arg("filter") = py::none(),
        py::arg("eye") = py::none(), py::arg("look_at") = py::none(), py::arg("up") = py::none(),
        py::arg("fov") = py::none(), py::arg("accel") = "grid", py::arg("threads") = py::none(),
        py::arg("progress") = false, R"doc(
The image vox-trace renders, pixel for pixel, as float32: (H, W, 3) linear RGB for modes 'shade', 'voxels',
'count', 'normals'; (H, W) for 'depth' (distance along the unit ray direction, 0 where nothing is hit). Rows from
the top; size is (width, height). The options are vox-trace's: samples per pixel (jittered), bounces and weight
(reflection and refraction), shade_back, shadows (False: --no-shadows), filter=(kind, radius) ('box', 'tent',
'gaussian'; pixels); eye and look_at (a perspective camera replacing the scene's), up, fov (vertical, degrees);
accel 'grid', 'uniform' (every cell crossed) or 'none' (brute force), the same image. Without a camera in the scene, one framing the grid; without
lights, a headlight. The GIL is released; Ctrl-C stops it. Write the result with libvox.save_image.
)doc");
  m.def("save_image", &saveImage, py::arg("path"), py::arg("image"), R"doc(
Writes an image as vox-trace writes it, format from the extension (.png .exr .tga .jpg .tif ...): float formats get
the values as they are, 8-bit formats clamped to [0, 1] and rounded. A (H, W) image is a depth image: float formats
get it as channel Z, 8-bit formats as vox-trace's grey (near bright, 0 for no hit). Through a temporary file and a
rename. UsageError for an unknown extension, OSError when it cannot be written.
)doc");
}

}  // namespace voxpy
