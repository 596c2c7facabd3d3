// Arguments at the border: numpy arrays and sequences checked for dtype, shape and values, converted once.
#include <cmath>
#include <cstdint>
#include <sstream>
#include <type_traits>

#include "binding.h"
#include "vox/core/error.h"

namespace voxpy {

namespace {

std::string typeName(const py::handle& obj) { return py::str(py::type::of(obj).attr("__name__")); }

std::string shapeText(const py::array& a) {
  std::ostringstream out;
  out << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) out << (d ? ", " : "") << a.shape(d);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

// np.asarray(obj), or TypeError naming `name`.
py::array asArray(const py::handle& obj, const char* name) {
  if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
  py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error(std::string(name) + " must be an array or a sequence of numbers, not " + typeName(obj));
  return a;
}

// The dtype's kind ('f', 'i', 'u', 'b', ...) and size.
char kindOf(const py::array& a) { return a.dtype().kind(); }

void requireShape(const py::array& a, const char* name, const char* expected, py::ssize_t columns) {
  if (a.ndim() != 2 || a.shape(1) != columns)
    vox::fail<vox::InputError>(name, ": expected an array of shape ", expected, ", got shape ", shapeText(a));
}

// TypeError unless the array holds floats of at most 64 bits or integers.
void requireNumeric(const py::array& a, const char* name) {
  const char kind = kindOf(a);
  if ((kind == 'f' && a.dtype().itemsize() <= 8) || kind == 'i' || kind == 'u') return;
  throw py::type_error(std::string(name) + " must hold floats (float32 or float64) or integers, not " +
                       std::string(py::str(a.dtype())));
}

// Coordinates as a C-contiguous float64 array, converted exactly: floats up to 64 bits widen exactly, integers are
// checked to lie within 2^53 (where doubles hold every integer).
py::array_t<double> exactDoubles(const py::array& a, const char* name) {
  const char kind = kindOf(a);
  const auto size = a.dtype().itemsize();
  if (kind == 'f' && size <= 8) return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (kind == 'i' || kind == 'u') {
    if (size == 8) {
      constexpr double kExact = 9007199254740992.0;  // 2^53
      if (kind == 'i') {
        auto v = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t n = 0; n < v.size(); ++n)
          if (std::fabs(double(v.data()[n])) > kExact)
            vox::fail<vox::InputError>(name, ": the integer ", v.data()[n], " has no exact double");
      } else {
        auto v = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t n = 0; n < v.size(); ++n)
          if (double(v.data()[n]) > kExact)
            vox::fail<vox::InputError>(name, ": the integer ", v.data()[n], " has no exact double");
      }
    }
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  }
  throw py::type_error(std::string(name) + " must hold floats (float32 or float64) or integers, not " +
                       std::string(py::str(a.dtype())));
}

}  // namespace

std::vector<vox::Vec3> vec3Array(const py::handle& obj, const char* name, bool allowEmpty) {
  const py::array a = asArray(obj, name);
  requireNumeric(a, name);
  requireShape(a, name, "(N, 3)", 3);
  const py::array_t<double> d = exactDoubles(a, name);
  const size_t n = size_t(d.shape(0));
  if (n == 0 && !allowEmpty) vox::fail<vox::InputError>(name, ": empty array (shape ", shapeText(a), ")");
  const double* p = d.data();
  std::vector<vox::Vec3> out(n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(p[3 * i + c]))
        vox::fail<vox::InputError>(name, "[", i, ", ", c, "] is ", p[3 * i + c], ": coordinates must be finite");
    out[i] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
  }
  return out;
}

std::vector<std::array<uint32_t, 3>> faceArray(const py::handle& obj, const char* name, size_t vertexCount) {
  const py::array a = asArray(obj, name);
  const char kind = kindOf(a);
  if (kind != 'i' && kind != 'u')
    throw py::type_error(std::string(name) + " must hold integers (vertex indices), not " +
                         std::string(py::str(a.dtype())));
  requireShape(a, name, "(F, 3)", 3);
  if (a.shape(0) == 0) vox::fail<vox::InputError>(name, ": empty array (shape ", shapeText(a), "): no triangles");
  std::vector<std::array<uint32_t, 3>> out(size_t(a.shape(0)));
  auto check = [&](auto value, size_t f, int c) {
    bool bad = uint64_t(value) >= vertexCount;
    if constexpr (std::is_signed_v<decltype(value)>) bad = bad || value < 0;
    if (bad)
      vox::fail<vox::InputError>(name, "[", f, ", ", c, "] = ", value, ": out of range for ", vertexCount,
                                 " vertices (indices count from 0)");
    out[f][c] = uint32_t(value);
  };
  if (kind == 'u') {
    auto v = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    for (size_t f = 0; f < out.size(); ++f)
      for (int c = 0; c < 3; ++c) check(v.data()[3 * f + c], f, c);
  } else {
    auto v = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    for (size_t f = 0; f < out.size(); ++f)
      for (int c = 0; c < 3; ++c) check(v.data()[3 * f + c], f, c);
  }
  return out;
}

vox::Scene sceneFromArrays(const py::handle& vertices, const py::handle& faces) {
  const std::vector<vox::Vec3> v = vec3Array(vertices, "vertices");
  if (v.size() > UINT32_MAX) vox::fail<vox::LimitError>("vertices: more than 2^32 - 1 vertices");
  const auto f = faceArray(faces, "faces", v.size());
  vox::Scene scene;
  scene.materials.push_back(vox::Material{"default"});
  scene.triangles.resize(f.size());
  for (size_t i = 0; i < f.size(); ++i) scene.triangles[i].v = {v[f[i][0]], v[f[i][1]], v[f[i][2]]};
  return scene;
}

vox::Vec3 vec3Arg(const py::handle& obj, const char* name) {
  const py::array a = asArray(obj, name);
  requireNumeric(a, name);
  if (a.ndim() != 1 || a.shape(0) != 3)
    vox::fail<vox::UsageError>(name, ": expected 3 numbers, got shape ", shapeText(a));
  const py::array_t<double> d = exactDoubles(a, name);
  const vox::Vec3 v{d.data()[0], d.data()[1], d.data()[2]};
  if (!vox::isFinite(v)) vox::fail<vox::UsageError>(name, ": expected finite numbers");
  return v;
}

std::array<uint32_t, 3> dims3Arg(const py::handle& obj, const char* name) {
  py::array a = asArray(obj, name);
  if (a.ndim() == 0) a = asArray(py::make_tuple(obj, obj, obj), name);  // one count for every axis
  if (a.ndim() != 1 || a.shape(0) != 3)
    vox::fail<vox::UsageError>(name, ": expected 3 cell counts, got shape ", shapeText(a));
  if (kindOf(a) != 'i' && kindOf(a) != 'u')
    throw py::type_error(std::string(name) + " must hold integers, not " + std::string(py::str(a.dtype())));
  auto v = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
  std::array<uint32_t, 3> out{};
  for (int c = 0; c < 3; ++c) {
    if (v.data()[c] < 1 || v.data()[c] > int64_t(UINT32_MAX))
      vox::fail<vox::UsageError>(name, ": ", v.data()[c], " cells on axis ", "xyz"[c], " (at least 1)");
    out[c] = uint32_t(v.data()[c]);
  }
  return out;
}

vox::Box boxArg(const py::handle& obj, const char* name) {
  const py::array a = asArray(obj, name);
  requireNumeric(a, name);
  if (a.ndim() != 2 || a.shape(0) != 2 || a.shape(1) != 3)
    vox::fail<vox::UsageError>(name, ": expected ((x0, y0, z0), (x1, y1, z1)), got shape ", shapeText(a));
  const py::array_t<double> d = exactDoubles(a, name);
  const double* p = d.data();
  return vox::Box{{p[0], p[1], p[2]}, {p[3], p[4], p[5]}};
}

std::optional<std::string> pathArg(const py::handle& obj) {
  if (py::isinstance<py::str>(obj)) return obj.cast<std::string>();
  if (py::isinstance<py::bytes>(obj) || py::hasattr(obj, "__fspath__")) {
    const py::module_ os = py::module_::import("os");
    return os.attr("fsdecode")(os.attr("fspath")(obj)).cast<std::string>();
  }
  return std::nullopt;
}

}  // namespace voxpy
