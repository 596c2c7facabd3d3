// The library's exceptions as Python exceptions (DESIGN.md "Python"): InputError(ValueError),
// UsageError(ValueError), LimitError(MemoryError), OutputError -> OSError; the message is the library's, naming the
// file and the place. Every message, the library's and the binding's, is decoded with replacement: a scene's line or a
// path that is not UTF-8 must not turn the error into a UnicodeDecodeError (or an empty one).
#include "binding.h"
#include "vox/core/error.h"

namespace voxpy {

namespace {

// Created once at import and kept for the life of the interpreter (like the module itself).
PyObject* inputError = nullptr;
PyObject* usageError = nullptr;
PyObject* limitError = nullptr;

PyObject* newException(py::module_& m, const char* name, PyObject* base, const char* doc) {
  const std::string qualified = std::string("libvox.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
  if (!type) throw py::error_already_set();
  m.add_object(name, py::handle(type));
  return type;
}

// Sets the Python error `type` with the message bytes `what`, decoded with replacement.
void setError(PyObject* type, const char* what) { PyErr_SetObject(type, messageText(what).ptr()); }

}  // namespace

void bindErrors(py::module_& m) {
  inputError = newException(m, "InputError", PyExc_ValueError,
                            "Malformed or out-of-range input: a scene or grid file (the message names the file and "
                            "the place: line, node, accessor or byte offset), or an array argument (wrong shape, NaN, "
                            "an index out of range, empty).");
  usageError = newException(m, "UsageError", PyExc_ValueError,
                            "Invalid or inconsistent options (the command-line tools' exit code 1): an unknown "
                            "method or mode, bounds with min >= max, two of resolution/dims/pitch, ...");
  limitError = newException(m, "LimitError", PyExc_MemoryError,
                            "A valid request that cannot be met: the grid, array or image would not fit in the memory "
                            "budget (three quarters of physical memory, or VOX_MEMORY_LIMIT_MB). Checked before "
                            "allocating.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vox::InputError& e) {
      setError(inputError, e.what());
    } catch (const vox::UsageError& e) {
      setError(usageError, e.what());
    } catch (const vox::LimitError& e) {
      setError(limitError, e.what());
    } catch (const vox::OutputError& e) {
      setError(PyExc_OSError, e.what());
    } catch (const vox::Error& e) {
      setError(PyExc_RuntimeError, e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(limitError, "out of memory");
    } catch (const py::cast_error& e) {
      // pybind11's "Unable to cast Python instance": a value of the wrong type, whatever pybind11 calls it.
      setError(PyExc_TypeError, e.what());
    } catch (const py::type_error& e) {
      setError(PyExc_TypeError, e.what());
    } catch (const py::value_error& e) {
      setError(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace voxpy
