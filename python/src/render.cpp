// libvox.render and libvox.save_image: vox-trace's image as a numpy array, and its image writer.
#include <cmath>

#include "binding.h"
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

template <class T>
T uintArg(const py::object& obj, const char* name, T lo, T hi) {
  if (py::isinstance<py::bool_>(obj) || !py::isinstance<py::int_>(obj))
    throw py::type_error(std::string(name) + " must be an int, not " +
                         std::string(py::str(py::type::of(obj).attr("__name__"))));
  const long long v = obj.cast<long long>();
  if (v < (long long)lo || v > (long long)hi) vox::fail<vox::UsageError>(name, " must be ", lo, "..", hi, ", got ", v);
  return T(v);
}

// The scene's camera (or one framing the grid) with vox-trace's overrides --eye/--look-at, --up, --fov applied, in
// the same way (tools/trace/main.cpp, resolveCamera).
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
    cam.up = scene.up;
    cam.fovDegrees = scene.kind == CameraKind::Perspective ? scene.fovDegrees : 45;
    // The scene's angle keeps the side it spans, so that moving the eye keeps the framing's width.
    if (scene.kind == CameraKind::Perspective) cam.span = scene.span;
    if (!(length(cam.direction) > 0)) fail<UsageError>("eye and look_at must differ");
  }
  if (!up.is_none()) cam.up = vec3Arg(up, "up");
  if (!fov.is_none()) {
    const double f = fov.cast<double>();
    if (!(f > 0 && f < 180)) fail<UsageError>("fov must be between 0 and 180 degrees, got ", f);
    cam.kind = CameraKind::Perspective;
    cam.fovDegrees = f;
    cam.span = CameraSpan::Height;  // fov is vertical, whatever the scene's camera spans
  }
  validateCamera(cam, "camera");
  return cam;
}

py::array_t<float> render(PyGrid& self, const py::object& size, const std::string& mode, const py::object& samples,
                          const py::object& bounces, double weight, bool shadeBack, bool shadows,
                          const py::object& filter, const py::object& eye, const py::object& lookAt,
                          const py::object& up, const py::object& fov, const std::string& accelName,
                          const py::object& threads, const py::object& progress) {
  using namespace vox;
  RenderOptions ro;
  ro.mode = parseRenderMode(mode);
  const AccelKind accelKind = parseAccel(accelName);
  if (!py::isinstance<py::sequence>(size) || py::len(size) != 2) fail<UsageError>("size must be (width, height)");
  const py::sequence wh = py::reinterpret_borrow<py::sequence>(size);
  ro.width = uintArg<uint32_t>(wh[0], "width", 1, kMaxSide);
  ro.height = uintArg<uint32_t>(wh[1], "height", 1, kMaxSide);
  if (uint64_t(ro.width) * ro.height > kMaxPixels) fail<UsageError>("size: at most 2^28 pixels");
  ro.samples = uintArg<uint32_t>(samples, "samples", 1, kMaxSamples);
  ro.bounces = uintArg<uint32_t>(bounces, "bounces", 0, kMaxBounces);
  if (!(std::isfinite(weight) && weight >= 0)) fail<UsageError>("weight must be a finite number >= 0");
  ro.weight = weight;
  ro.shadeBack = shadeBack;
  ro.shadows = shadows;
  if (!filter.is_none()) {
    if (!py::isinstance<py::sequence>(filter) || py::isinstance<py::str>(filter) || py::len(filter) != 2)
      fail<UsageError>("filter must be (kind, radius): ('box' | 'tent' | 'gaussian', pixels)");
    const py::sequence f = py::reinterpret_borrow<py::sequence>(filter);
    ro.filter = parseFilter(f[0].cast<std::string>());
    ro.filterRadius = f[1].cast<double>();
    if (!(ro.filterRadius > 0 && ro.filterRadius <= kMaxFilterRadius))
      fail<UsageError>("filter radius must be in (0, ", kMaxFilterRadius, "] pixels");
  }
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

void saveImage(const py::object& pathObj, const py::handle& pixels) {
  const auto path = pathArg(pathObj);
  if (!path) throw py::type_error("path must be a str or os.PathLike");
  const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(pixels);
  if (!a) throw py::type_error("image must be an array of numbers");
  const bool depth = a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1);
  if (!(depth || (a.ndim() == 3 && a.shape(2) == 3)) || a.shape(0) == 0 || a.shape(1) == 0)
    vox::fail<vox::InputError>("image: expected shape (H, W, 3) or (H, W), got ", a.ndim(), " dimensions");
  if (!vox::imageFormatSupported(*path))
    vox::fail<vox::UsageError>(*path, ": unknown image format (use an extension such as .png, .tga, .exr, .jpg)");
  vox::Image image;
  image.height = uint32_t(a.shape(0));
  image.width = uint32_t(a.shape(1));
  image.channels = depth ? 1 : 3;
  image.pixels.assign(a.data(), a.data() + a.size());
  py::gil_scoped_release release;
  if (depth && !vox::imageFormatHoldsFloat(*path)) image = vox::depthToGrey(image);
  vox::writeImage(*path, image);
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
