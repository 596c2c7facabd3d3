// The one conversion layer every function of the package passes its arguments through (STYLE.md convention 17):
// paths, integers, floats, bools, enums and small sequences, so that a wrong type raises TypeError and a wrong value
// UsageError (a ValueError) everywhere, each message naming the argument. Messages are built with the library's
// formatter (vox::fail) and decoded with replacement when they become Python strings, so that no byte of an input
// (a path, a line of a scene file) can raise UnicodeDecodeError in place of the error it describes.
#pragma once

#include <pybind11/pybind11.h>

#include <array>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/math.h"

namespace voxpy {

namespace py = pybind11;

// The Python type's name of `obj`, as messages show it ("int", "str", "numpy.int64").
std::string typeName(const py::handle& obj);

// TypeError with a message built as vox::fail builds one.
template <typename... Parts>
[[noreturn]] void failType(const Parts&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  throw py::type_error(out.str());
}

// A Python str of message bytes, invalid UTF-8 replaced by U+FFFD.
py::str messageText(const std::string& bytes);
// A UserWarning of `message` (decoded with replacement), attributed to the caller's line.
void warn(const std::string& message);

// ---- Paths ----

// Whether `obj` is a str, bytes or os.PathLike.
bool isPath(const py::handle& obj);
// The file system bytes of a str, bytes or os.PathLike (os.fsencode: a name that is valid on Linux but not UTF-8
// comes through as its bytes). TypeError naming `name` for another type; UsageError for a NUL byte, which the file
// system would cut the name at.
std::string pathArg(const py::handle& obj, const std::string& name);
// Path bytes as Python gives a path back (os.fsdecode; pathArg of the result gives the bytes again).
py::str pathText(const std::string& path);

// ---- Numbers ----

// An integer: anything with __index__ (int, numpy integers, 0-d integer arrays) except bool and numpy.bool_.
// TypeError naming `name` for another type; UsageError "`name` must be lo..hi, got v" outside [lo, hi] (also for
// values beyond 64 bits).
int64_t intArg(const py::handle& obj, const std::string& name, int64_t lo, int64_t hi);
// A real number: int, float, numpy integers and floats (numbers.Real), not bool, complex or str. TypeError naming
// `name` otherwise; UsageError for an integer without an exact double, NaN, and infinity unless `allowInfinite`.
double floatArg(const py::handle& obj, const std::string& name, bool allowInfinite = false);
// True or False (bool or numpy.bool_); TypeError naming `name` otherwise. None counts as False when `allowNone`.
bool boolArg(const py::handle& obj, const std::string& name, bool allowNone = false);
// Whether `obj` is a bool or a numpy.bool_.
bool isBool(const py::handle& obj);

// ---- Enums and sequences ----

// A str; TypeError naming `name` otherwise.
std::string strArg(const py::handle& obj, const std::string& name);
// A value parsed by the library's parser (vox::parseMethod, ...), whose InputError or UsageError becomes a UsageError
// naming `name`: a bad option is the caller's usage, not a bad file.
template <class Parse>
auto optionArg(const std::string& name, const std::string& value, Parse&& parse) {
  try {
    return parse(value);
  } catch (const vox::InputError& e) {
    throw vox::UsageError(name + ": " + e.what());
  } catch (const vox::UsageError& e) {
    throw vox::UsageError(name + ": " + e.what());
  }
}
// An enum option: a str (TypeError naming `name` otherwise) parsed as optionArg parses it.
template <class Parse>
auto enumArg(const py::handle& obj, const std::string& name, Parse&& parse) {
  return optionArg(name, strArg(obj, name), parse);
}
// Whether `obj` is a list, tuple, numpy array of at least one dimension or another sequence that is not a str,
// bytes or bytearray.
bool isSequence(const py::handle& obj);
// The `count` items of a sequence (as isSequence). TypeError naming `name` for another type (`what` says what was
// expected), UsageError for another length.
std::vector<py::object> sequenceArg(const py::handle& obj, const std::string& name, size_t count, const char* what);

// Three finite numbers (a sequence of 3), each as floatArg names it: "eye[0]".
vox::Vec3 vec3Arg(const py::handle& obj, const std::string& name);
// Cell counts: one int for all three axes, or a sequence of 3, each in [1, max].
std::array<uint32_t, 3> dims3Arg(const py::handle& obj, const std::string& name, uint32_t max);
// ((x0, y0, z0), (x1, y1, z1)) or a (2, 3) array: finite, min below max on every axis and max - min a finite
// double (the grid's cells are computed from it). UsageError otherwise.
vox::Box boxArg(const py::handle& obj, const std::string& name);
// The worker threads of a call: nullopt for None, else 1..4096 (as intArg).
std::optional<int> threadsArg(const py::handle& threads);

// ---- Calls that do not fit a signature ----

// Gives every function of `scope` (the module, or the Grid class for its methods) whose parameters are all objects
// or Grids a last overload, reached only when a call does not fit the signature (an unknown keyword, one positional
// argument too many, a missing or repeated one, a Grid argument that is not a Grid): it raises TypeError naming that
// argument, as Python does for its own functions ("sdf() got an unexpected keyword argument 'method'"), in place of
// pybind11's "incompatible function arguments" and its list of C++ signatures. `grid`: the Grid class. Call once
// all are defined.
void nameBadCalls(py::handle scope, py::handle grid);
// The pybind11 record of a bound function (a module's function, or a method's as the class gives it), or null for
// anything else.
py::detail::function_record* functionRecord(const py::handle& function);

}  // namespace voxpy
