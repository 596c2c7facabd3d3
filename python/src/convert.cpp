// The conversion layer of every argument (convert.h).
#include "convert.h"

#include <pybind11/numpy.h>

#include <cmath>
#include <cstring>

#include "vox/core/error.h"

namespace voxpy {

namespace {

// Python objects looked up once per interpreter: numpy.bool_ (whose __index__ would make it an integer) and
// numbers.Real (what a float argument takes: int, float, numpy's real scalars, fractions).
struct Types {
  py::object numpyBool, real;
};

const Types& types() {
  static const Types* t = new Types{py::module_::import("numpy").attr("bool_"),
                                    py::module_::import("numbers").attr("Real")};  // never freed: the interpreter's
  return *t;
}

std::string shortRepr(const py::handle& obj) {
  // A repr for messages: the value as the caller wrote it, cut short (a huge int, a long string).
  std::string r = py::repr(obj).cast<std::string>();
  return r.size() > 60 ? r.substr(0, 57) + "..." : r;
}

}  // namespace

std::string typeName(const py::handle& obj) {
  const py::handle type = py::type::of(obj);
  std::string module = py::str(type.attr("__module__"));
  const std::string name = py::str(type.attr("__qualname__"));
  return module == "builtins" ? name : module + "." + name;
}

py::str messageText(const std::string& bytes) {
  PyObject* s = PyUnicode_DecodeUTF8(bytes.data(), py::ssize_t(bytes.size()), "replace");
  if (!s) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(s);
}

void warn(const std::string& message) {
  const py::str text = messageText(message);
  if (PyErr_WarnFormat(PyExc_UserWarning, 1, "%U", text.ptr()) != 0) throw py::error_already_set();
}

bool isPath(const py::handle& obj) {
  return py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj) || py::hasattr(py::type::of(obj), "__fspath__");
}

std::string pathArg(const py::handle& obj, const std::string& name) {
  if (!isPath(obj)) failType(name, " must be a path (str, bytes or os.PathLike), not ", typeName(obj));
  // os.fsencode: str through the file system encoding with surrogateescape, as open() does.
  const py::bytes encoded = py::module_::import("os").attr("fsencode")(obj);
  std::string path = encoded;
  if (path.find('\0') != std::string::npos)
    vox::fail<vox::UsageError>(name, ": embedded null byte in ", shortRepr(obj));
  return path;
}

py::str pathText(const std::string& path) { return py::module_::import("os").attr("fsdecode")(py::bytes(path)); }

bool isBool(const py::handle& obj) { return py::isinstance<py::bool_>(obj) || py::isinstance(obj, types().numpyBool); }

int64_t intArg(const py::handle& obj, const std::string& name, int64_t lo, int64_t hi) {
  if (isBool(obj)) failType(name, " must be an int, not bool");
  PyObject* index = PyNumber_Index(obj.ptr());
  if (!index) {
    PyErr_Clear();
    failType(name, " must be an int, not ", typeName(obj));
  }
  const py::object value = py::reinterpret_steal<py::object>(index);
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
  if (overflow == 0 && v == -1 && PyErr_Occurred()) throw py::error_already_set();
  if (overflow != 0 || v < lo || v > hi)
    vox::fail<vox::UsageError>(name, " must be ", lo, "..", hi, ", got ", std::string(py::str(value)));
  return v;
}

double floatArg(const py::handle& obj, const std::string& name, bool allowInfinite) {
  if (isBool(obj) || !py::isinstance(obj, types().real)) failType(name, " must be a number, not ", typeName(obj));
  double d;
  if (PyObject* index = PyNumber_Index(obj.ptr())) {
    // An integer: exact only when the double holds it (every one up to 2^53); nothing is rounded silently.
    const py::object i = py::reinterpret_steal<py::object>(index);
    d = PyLong_AsDouble(i.ptr());
    if (d == -1.0 && PyErr_Occurred()) PyErr_Clear(), d = HUGE_VAL;
    if (!std::isfinite(d) || !py::float_(d).equal(i))
      vox::fail<vox::UsageError>(name, ": the integer ", shortRepr(i), " has no exact double");
    return d;
  }
  PyErr_Clear();
  d = PyFloat_AsDouble(obj.ptr());
  if (d == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    vox::fail<vox::UsageError>(name, ": ", shortRepr(obj), " is not a double");
  }
  if (std::isnan(d) || (!allowInfinite && std::isinf(d)))
    vox::fail<vox::UsageError>(name, " must be a finite number, got ", d);
  return d;
}

bool boolArg(const py::handle& obj, const std::string& name, bool allowNone) {
  if (allowNone && obj.is_none()) return false;
  if (!isBool(obj)) failType(name, " must be True or False", allowNone ? " (or None)" : "", ", not ", typeName(obj));
  return PyObject_IsTrue(obj.ptr()) == 1;
}

std::string strArg(const py::handle& obj, const std::string& name) {
  if (!py::isinstance<py::str>(obj)) failType(name, " must be a str, not ", typeName(obj));
  // Encoded with surrogateescape so that a lone surrogate cannot raise UnicodeEncodeError; the parser refuses it.
  const py::bytes b =
      py::reinterpret_steal<py::bytes>(PyUnicode_AsEncodedString(obj.ptr(), "utf-8", "surrogateescape"));
  if (!b) throw py::error_already_set();
  return std::string(b);
}

bool isSequence(const py::handle& obj) {
  if (py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj) || PyByteArray_Check(obj.ptr())) return false;
  if (py::isinstance<py::array>(obj)) return py::reinterpret_borrow<py::array>(obj).ndim() > 0;
  return PySequence_Check(obj.ptr()) == 1 && !PyDict_Check(obj.ptr());
}

std::vector<py::object> sequenceArg(const py::handle& obj, const std::string& name, size_t count, const char* what) {
  if (!isSequence(obj)) failType(name, " must be ", what, ", not ", typeName(obj));
  const py::ssize_t n = PySequence_Size(obj.ptr());
  if (n < 0) throw py::error_already_set();
  if (size_t(n) != count) vox::fail<vox::UsageError>(name, ": expected ", what, ", got ", n, " items");
  std::vector<py::object> items;
  for (py::ssize_t i = 0; i < n; ++i) {
    PyObject* item = PySequence_GetItem(obj.ptr(), i);
    if (!item) throw py::error_already_set();
    items.push_back(py::reinterpret_steal<py::object>(item));
  }
  return items;
}

vox::Vec3 vec3Arg(const py::handle& obj, const std::string& name) {
  const auto items = sequenceArg(obj, name, 3, "3 numbers");
  vox::Vec3 v;
  for (int a = 0; a < 3; ++a) v.at(a) = floatArg(items[size_t(a)], name + "[" + std::to_string(a) + "]");
  return v;
}

std::array<uint32_t, 3> dims3Arg(const py::handle& obj, const std::string& name, uint32_t max) {
  std::array<uint32_t, 3> out{};
  if (!isSequence(obj)) {  // one count for every axis
    out.fill(uint32_t(intArg(obj, name, 1, max)));
    return out;
  }
  const auto items = sequenceArg(obj, name, 3, "an int or 3 ints");
  for (size_t a = 0; a < 3; ++a) out[a] = uint32_t(intArg(items[a], name + "[" + std::to_string(a) + "]", 1, max));
  return out;
}

vox::Box boxArg(const py::handle& obj, const std::string& name) {
  const auto corners = sequenceArg(obj, name, 2, "((x0, y0, z0), (x1, y1, z1))");
  const vox::Box b{vec3Arg(corners[0], name + "[0]"), vec3Arg(corners[1], name + "[1]")};
  for (int a = 0; a < 3; ++a) {
    if (!(b.lo[a] < b.hi[a]))
      vox::fail<vox::UsageError>(name, ": minimum must be below maximum on every axis (", "xyz"[a], ": ", b.lo[a],
                                 " and ", b.hi[a], ")");
    if (!std::isfinite(b.hi[a] - b.lo[a]))
      vox::fail<vox::UsageError>(name, ": the extent on axis ", "xyz"[a], " (", b.lo[a], " to ", b.hi[a],
                                 ") is wider than the largest double: no grid can divide it");
  }
  return b;
}

std::optional<int> threadsArg(const py::handle& threads) {
  if (threads.is_none()) return std::nullopt;
  return int(intArg(threads, "threads", 1, 4096));
}

}  // namespace voxpy
