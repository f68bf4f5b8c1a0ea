// convert.h — Python <-> C++ conversions for cloudgen_native (stable ABI only).
//
// Conventions inside the bindings:
//   * Every Python C-API failure that leaves a Python exception set is turned
//     into a C++ `PyErrorSet` throw; every C++ exception is translated into a
//     Python exception in exactly one place, `guarded()` (ParamError → ValueError,
//     bad_alloc → MemoryError, anything else → RuntimeError).
//   * Owned references live in `Ref` (released on scope exit), so early exits
//     and throws never leak.
#pragma once

#ifndef Py_LIMITED_API
#define Py_LIMITED_API 0x030B0000  // CMake defines it (USE_SABI 3.11); keep the same value here
#endif
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <exception>
#include <string>
#include <utility>

#include "cloudgen/params.h"

namespace cgpy {

// Thrown when a Python API call failed and the Python error indicator is set.
struct PyErrorSet {};

// Raise `type` with `message` and throw PyErrorSet.
[[noreturn]] void raise(PyObject* type, const std::string& message);

// An owned (strong) reference; steals what it is given.
class Ref {
 public:
  Ref() = default;
  explicit Ref(PyObject* p) : p_(p) {}
  Ref(const Ref&) = delete;
  Ref& operator=(const Ref&) = delete;
  Ref(Ref&& o) noexcept : p_(o.p_) { o.p_ = nullptr; }
  Ref& operator=(Ref&& o) noexcept {
    std::swap(p_, o.p_);
    return *this;
  }
  ~Ref() { Py_XDECREF(p_); }
  PyObject* get() const { return p_; }
  PyObject* release() {
    PyObject* p = p_;
    p_ = nullptr;
    return p;
  }
  explicit operator bool() const { return p_ != nullptr; }

 private:
  PyObject* p_ = nullptr;
};

// Steals `p`; throws PyErrorSet when it is null (the API call failed).
Ref check(PyObject* p);
// Throws PyErrorSet when `status` < 0.
void check_status(int status);

// The one place where C++ exceptions become Python exceptions. Must be called
// from inside a `catch` block, with the GIL held.
void set_python_error_from_current_exception() noexcept;

// Runs `f` (returning a new reference) and translates anything it throws.
template <class F>
PyObject* guarded(F&& f) noexcept {
  try {
    return f();
  } catch (...) {
    set_python_error_from_current_exception();
    return nullptr;
  }
}

// Runs `f` with the GIL released (Py_BEGIN/END_ALLOW_THREADS); an exception
// thrown by `f` is carried across and rethrown once the GIL is held again.
template <class F>
void without_gil(F&& f) {
  std::exception_ptr error;
  Py_BEGIN_ALLOW_THREADS try { f(); } catch (...) {
    error = std::current_exception();
  }
  Py_END_ALLOW_THREADS if (error) std::rethrow_exception(error);
}

// ---- scalars ----

// Short repr of any object for messages (never throws; "<?>" on failure).
std::string repr(PyObject* o);
// Name of an object's type for messages, e.g. "str".
std::string type_name(PyObject* o);
// A float32 value as a Python float with the shortest decimal that reads back
// as the same float32 (0.85f → 0.85, not 0.8500000238418579).
Ref float_to_py(float v);
// A Python str from UTF-8 text.
Ref str_to_py(const char* s);
// A Python integer argument that is not a bool; `what` names it in messages.
long long int_arg(PyObject* o, const char* what);
// A finite Python number (int or float, not bool) as double; `what` names it.
double number_arg(PyObject* o, const char* what);

// ---- dicts ----

// dict[key] = value for a fixed key.
void set_item(PyObject* dict, const char* key, Ref value);

// ---- parameters ----

// The value of parameter `p` in `params` as Python (float, int, or list).
Ref param_value_to_py(const cg::Params& params, cg::P p);
// Every parameter of `params` as a dict keyed by declared name.
Ref params_to_py(const cg::Params& params);
// One declaration as a dict (name, label, group, kind, count, default, min,
// max, soft_min, soft_max, map, unit, help).
Ref declaration_to_py(cg::P p);
// A params dict (or None for the defaults) to validated cg::Params. The
// optional key "preset" names the base cloud type; every other key must be a
// declared parameter. Throws cg::ParamError (→ ValueError) or raises TypeError
// naming the key and the accepted range.
cg::Params params_from_py(PyObject* obj);

}  // namespace cgpy
