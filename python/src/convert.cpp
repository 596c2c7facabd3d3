// The conversion layer of every argument (convert.h).
#include "convert.h"

#include <pybind11/numpy.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "vox/core/error.h"
#include "vox/core/exact_number.h"

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
      vox::fail<vox::UsageError>(name, ": minimum must be below maximum on every axis (", "xyz"[a], ": ",
                                 vox::exactNumber(b.lo[a]), " and ", vox::exactNumber(b.hi[a]), ")");
    if (!std::isfinite(b.hi[a] - b.lo[a]))
      vox::fail<vox::UsageError>(name, ": the extent on axis ", "xyz"[a], " (", vox::exactNumber(b.lo[a]), " to ",
                                 vox::exactNumber(b.hi[a]),
                                 ") is wider than the largest double: no grid can divide it");
  }
  return b;
}

std::optional<int> threadsArg(const py::handle& threads) {
  if (threads.is_none()) return std::nullopt;
  return int(intArg(threads, "threads", 1, 4096));
}

// ---- Calls that do not fit a signature ----

namespace {

// What a bound function takes, read from its pybind11 record: the names pybind11 shows, which can be given by
// position, which have defaults, which must be Grids.
struct Signature {
  std::string name;  // "sdf", "Grid.save"
  bool method = false;
  std::vector<std::string> params;  // self first for a method
  std::vector<bool> hasDefault, isGrid;
  size_t positional = 0, positionalOnly = 0;
  py::object gridType;
};

// The parameters of `rec`, or nullopt when one is of a type that pybind11 converts (an int, a list): such a function
// keeps pybind11's own handling, since the overload added here would also catch its first, conversion-free pass.
std::optional<Signature> signatureOf(const py::detail::function_record& rec, const std::string& prefix,
                                     const py::handle& grid) {
  Signature s;
  s.name = prefix + rec.name;
  s.method = rec.is_method;
  s.positional = rec.nargs_pos;
  s.positionalOnly = rec.nargs_pos_only;
  s.gridType = py::reinterpret_borrow<py::object>(grid);
  const std::string gridName = py::str(grid.attr("__module__")).cast<std::string>() + "." +
                               py::str(grid.attr("__qualname__")).cast<std::string>();
  const std::string signature = rec.signature;
  size_t at = 0;
  for (size_t i = 0; i < rec.nargs; ++i) {
    std::string name = i < rec.args.size() && rec.args[i].name ? rec.args[i].name
                       : i == 0 && rec.is_method               ? "self"
                                                               : "arg" + std::to_string(i - size_t(rec.is_method));
    // pybind11 writes "name: type" or "name: type = default", in order.
    at = signature.find(name + ": ", at);
    if (at == std::string::npos) return std::nullopt;
    at += name.size() + 2;
    const std::string type = signature.substr(at, signature.find_first_of(",)= ", at) - at);
    if (type != "object" && type != "handle" && type != gridName) return std::nullopt;
    s.params.push_back(name);
    s.hasDefault.push_back(i < rec.args.size() && rec.args[i].value);
    s.isGrid.push_back(type == gridName);
  }
  return s;
}

std::string joined(const std::vector<std::string>& names, size_t from, size_t to) {
  std::string out;
  for (size_t i = from; i < to; ++i) out += (i > from ? ", " : "") + names[i];
  return out;
}

// Python's messages for a call that does not bind, each naming the argument.
[[noreturn]] void badCall(const Signature& s, const py::args& args, const py::kwargs& kwargs) {
  const size_t given = args.size(), self = s.method ? 1 : 0, n = s.params.size();
  if (s.method && (given == 0 || !py::isinstance(args[0], s.gridType)))
    failType(s.name, "() needs a libvox.Grid to work on, not ", given == 0 ? "nothing" : typeName(args[0]));
  if (given > s.positional) {
    const size_t most = s.positional - self;
    size_t required = self;
    while (required < s.positional && !s.hasDefault[required]) ++required;
    failType(s.name, "() takes ", required == s.positional ? "" : "at most ", most, " positional argument",
             most == 1 ? "" : "s", most ? " (" + joined(s.params, self, s.positional) + ")" : "", " but ", given - self,
             given - self == 1 ? " was" : " were", " given",
             s.positional < n ? "; " + joined(s.params, s.positional, n) + " are keyword-only (name=value)" : "");
  }
  std::vector<py::handle> bound(n);
  for (size_t i = 0; i < given; ++i) bound[i] = args[i];
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    const auto at = std::find(s.params.begin() + std::ptrdiff_t(self), s.params.end(), name);
    if (at == s.params.end())
      failType(s.name, "() got an unexpected keyword argument '", name, "' (it takes ", joined(s.params, self, n), ")");
    const size_t i = size_t(at - s.params.begin());
    if (i < given) failType(s.name, "() got multiple values for argument '", name, "'");
    if (i < s.positionalOnly) failType(s.name, "(): ", name, " is positional-only and cannot be given by name");
    bound[i] = value;
  }
  for (size_t i = self; i < n; ++i) {
    if (!bound[i] && !s.hasDefault[i]) failType(s.name, "() missing required argument '", s.params[i], "'");
    if (bound[i] && s.isGrid[i] && !py::isinstance(bound[i], s.gridType))
      failType(s.name, "(): ", s.params[i], " must be a libvox.Grid, not ", typeName(bound[i]));
  }
  failType(s.name, "(): these arguments do not fit its signature (", joined(s.params, self, n), ")");
}

}  // namespace

// The pybind11 record of a bound function, or null for anything else.
py::detail::function_record* functionRecord(const py::handle& function) {
  if (!function || !PyCFunction_Check(function.ptr())) return nullptr;
  const py::handle self = PyCFunction_GET_SELF(function.ptr());
  if (!self || !py::isinstance<py::capsule>(self)) return nullptr;
  const auto capsule = py::reinterpret_borrow<py::capsule>(self);
  if (!py::detail::is_function_record_capsule(capsule)) return nullptr;
  return capsule.get_pointer<py::detail::function_record>();
}

void nameBadCalls(py::handle scope, py::handle grid) {
  const bool isClass = PyType_Check(scope.ptr());
  const std::string prefix = isClass ? py::str(scope.attr("__name__")).cast<std::string>() + "." : "";
  const py::dict members(scope.attr("__dict__"));  // a copy: the loop adds to the scope's functions
  for (const auto& [key, value] : members) {
    const py::handle function = py::detail::get_function(value);  // a method's function
    py::detail::function_record* rec = functionRecord(function);
    if (!rec || rec->next || rec->is_constructor || rec->is_operator || rec->has_args || rec->has_kwargs) continue;
    const std::optional<Signature> signature = signatureOf(*rec, prefix, grid);
    if (!signature) continue;
    // The overload joins the function's chain (py::sibling), which rewrites its docstring as "Overloaded
    // function..."; the one-overload docstring, whose first line is the signature, is put back.
    const std::string doc = py::str(function.attr("__doc__"));
    auto fallback = [s = *signature](const py::args& args, const py::kwargs& kwargs) -> py::object {
      badCall(s, args, kwargs);
    };
    if (isClass)
      py::cpp_function(fallback, py::name(rec->name), py::is_method(scope), py::sibling(function));
    else
      py::cpp_function(fallback, py::name(rec->name), py::scope(scope), py::sibling(function));
    PyMethodDef* def = reinterpret_cast<PyCFunctionObject*>(function.ptr())->m_ml;
    std::free(const_cast<char*>(def->ml_doc));  // pybind11's strdup
    def->ml_doc = strdup(doc.c_str());
  }
}

}  // namespace voxpy
