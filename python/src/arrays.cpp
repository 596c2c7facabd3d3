// Arguments at the border: numpy arrays and sequences checked for dtype, shape and values, converted once.
#include <cmath>
#include <cstdint>
#include <sstream>
#include <type_traits>

#include "binding.h"
#include "vox/core/error.h"

namespace voxpy {

namespace {

std::string shapeText(const py::array& a) {
  std::ostringstream out;
  out << "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) out << (d ? ", " : "") << a.shape(d);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

// "dtype float16", "dtype object": a dtype as messages name it (a bare "object" reads as a type).
std::string dtypeText(const py::array& a) { return "dtype " + std::string(py::str(a.dtype())); }

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
  failType(name, " must hold floats (float32 or float64) or integers, not ", dtypeText(a));
}

// Coordinates as a C-contiguous float64 array, converted exactly: floats up to 64 bits widen exactly, 64-bit
// integers are checked to have an exact double (compared as integers: converting first would hide the rounding of
// 2^53 + 1 to 2^53); smaller integers always have one.
py::array_t<double> exactDoubles(const py::array& a, const char* name) {
  const char kind = kindOf(a);
  const auto size = a.dtype().itemsize();
  if (kind == 'f' && size <= 8) return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (kind == 'i' || kind == 'u') {
    if (size == 8) {
      constexpr double kTwo63 = 9223372036854775808.0, kTwo64 = 18446744073709551616.0;
      if (kind == 'i') {
        auto v = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t n = 0; n < v.size(); ++n) {
          const int64_t x = v.data()[n];
          const double d = double(x);
          if (d >= kTwo63 || int64_t(d) != x)
            vox::fail<vox::InputError>(name, ": the integer ", x, " has no exact double");
        }
      } else {
        auto v = py::array_t<uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t n = 0; n < v.size(); ++n) {
          const uint64_t x = v.data()[n];
          const double d = double(x);
          if (d >= kTwo64 || uint64_t(d) != x)
            vox::fail<vox::InputError>(name, ": the integer ", x, " has no exact double");
        }
      }
    }
    return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  }
  failType(name, " must hold floats (float32 or float64) or integers, not ", dtypeText(a));
}

}  // namespace

py::array asArray(const py::handle& obj, const char* name) {
  if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj);
  if (py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj))
    failType(name, " must be an array or a sequence of numbers, not ", typeName(obj));
  try {
    const py::array a = py::module_::import("numpy").attr("asarray")(obj);
    // numpy wraps anything else (None, a dict, a list of str) in an array of objects, whose dtype name "object"
    // would be all a message could say about it.
    if (kindOf(a) == 'O' && !isSequence(obj))
      failType(name, " must be an array of numbers (or a sequence of them), not ", typeName(obj));
    if (kindOf(a) == 'O')
      failType(name, " must be an array of numbers (or a sequence of them), not a ", typeName(obj),
               " of other objects");
    return a;
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError)) throw;
    vox::fail<vox::InputError>(
        name, ": not an array: rows of different lengths? (numpy: ", std::string(py::str(e.value())), ")");
  }
}

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
  if (kind != 'i' && kind != 'u') failType(name, " must hold integers (vertex indices), not ", dtypeText(a));
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

}  // namespace voxpy
