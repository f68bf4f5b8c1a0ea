// convert.cpp — Python <-> C++ conversions and the one exception translator.
#include "convert.h"

#include "cloudgen/names.h"

#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "cloudgen/param_io.h"

namespace cgpy {

// ---------------------------------------------------------------- errors ---

void raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw PyErrorSet{};
}

Ref check(PyObject* p) {
  if (!p) throw PyErrorSet{};
  return Ref(p);
}

void check_status(int status) {
  if (status < 0) throw PyErrorSet{};
}

void set_python_error_from_current_exception() noexcept {
  try {
    throw;
  } catch (const PyErrorSet&) {
    if (!PyErr_Occurred())
      PyErr_SetString(PyExc_SystemError, "cloudgen_native: an error was flagged without a Python exception");
  } catch (const cg::ParamError& e) {
    PyErr_SetString(PyExc_ValueError, e.what());
  } catch (const std::bad_alloc&) {
    PyErr_NoMemory();
  } catch (const std::exception& e) {
    PyErr_SetString(PyExc_RuntimeError, e.what());
  } catch (...) {
    PyErr_SetString(PyExc_RuntimeError, "cloudgen_native: unknown C++ exception");
  }
}

// --------------------------------------------------------------- scalars ---

// At most 100 characters of a name from the caller (a 10 MB key once became a 10 MB message).
static std::string clip(std::string_view s) {
  return s.size() > 100 ? std::string(s.substr(0, 100)) + "..." : std::string(s);
}

std::string repr(PyObject* o) {
  PyObject* r = PyObject_Repr(o);
  if (!r) {
    PyErr_Clear();
    return "<?>";
  }
  Py_ssize_t size = 0;
  const char* s = PyUnicode_AsUTF8AndSize(r, &size);
  std::string out = s ? std::string(s, static_cast<std::size_t>(size)) : std::string("<?>");
  if (!s) PyErr_Clear();
  Py_DECREF(r);
  if (out.size() > 80) out = out.substr(0, 77) + "...";
  return out;
}

std::string type_name(PyObject* o) {
  PyObject* type = PyObject_Type(o);
  if (!type) {
    PyErr_Clear();
    return "?";
  }
  PyObject* name = PyObject_GetAttrString(type, "__name__");
  Py_DECREF(type);
  if (!name) {
    PyErr_Clear();
    return "?";
  }
  const char* s = PyUnicode_Check(name) ? PyUnicode_AsUTF8AndSize(name, nullptr) : nullptr;
  std::string out = s ? s : "?";
  if (!s) PyErr_Clear();
  Py_DECREF(name);
  return out;
}

static std::string got(PyObject* o) { return "; got " + type_name(o) + " " + repr(o); }

Ref float_to_py(float v) {
  double d = static_cast<double>(v);
  if (std::isfinite(v)) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf - 1, v);  // shortest round-trip float32 text
    if (r.ec == std::errc()) {
      *r.ptr = '\0';
      d = std::strtod(buf, nullptr);
    }
  }
  return check(PyFloat_FromDouble(d));
}

Ref str_to_py(const char* s) { return check(PyUnicode_FromString(s)); }

// Python bool and numpy's bool scalars are refused where numbers are expected:
// True is far more likely a mistake than a deliberate 1.
static bool is_bool(PyObject* o) {
  if (PyBool_Check(o)) return true;
  const std::string name = type_name(o);
  return name == "bool_" || name == "bool";
}

long long int_arg(PyObject* o, const char* what) {
  if (is_bool(o) || !PyIndex_Check(o)) raise(PyExc_TypeError, std::string(what) + got(o));
  Ref index = check(PyNumber_Index(o));
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(index.get(), &overflow);
  if (v == -1 && PyErr_Occurred()) throw PyErrorSet{};
  if (overflow != 0) return overflow > 0 ? LLONG_MAX : LLONG_MIN;  // out of any range we accept
  return v;
}

double number_arg(PyObject* o, const char* what) {
  if (is_bool(o) || PyUnicode_Check(o) || PyBytes_Check(o) || PyByteArray_Check(o))
    raise(PyExc_TypeError, std::string(what) + got(o));
  if (PyFloat_Check(o)) return PyFloat_AsDouble(o);
  if (PyLong_Check(o)) {
    const double d = PyLong_AsDouble(o);
    if (d == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();  // OverflowError: an integer beyond any double is out of every range
      raise(PyExc_ValueError, std::string(what) + "; got an integer too large for a float");
    }
    return d;
  }
  // numpy scalars, 0-d arrays and other objects with __float__.
  PyObject* f = PyNumber_Float(o);
  if (!f) {
    if (!PyErr_ExceptionMatches(PyExc_TypeError)) throw PyErrorSet{};
    PyErr_Clear();
    raise(PyExc_TypeError, std::string(what) + got(o));
  }
  const double d = PyFloat_AsDouble(f);
  Py_DECREF(f);
  return d;
}

// ------------------------------------------------------------ parameters ---

void set_item(PyObject* dict, const char* key, Ref value) {
  // Not PyDict_SetItemString: it interns a temporary str per call, and the
  // interpreter's table of interned strings then churns (insert + delete) on
  // every call. The module keeps no static Python objects either.
  Ref k = str_to_py(key);
  check_status(PyDict_SetItem(dict, k.get(), value.get()));
}

Ref param_value_to_py(const cg::Params& params, cg::P p) {
  const cg::ParamDecl& d = cg::kParams[p];
  const int n = cg::component_count(d.kind);
  if (n == 1) {
    if (d.kind == cg::Kind::Int) return check(PyLong_FromLongLong(static_cast<long long>(params.get(p))));
    return float_to_py(params.get(p));
  }
  Ref list = check(PyList_New(n));
  for (int c = 0; c < n; ++c) check_status(PyList_SetItem(list.get(), c, float_to_py(params.get(p, c)).release()));
  return list;
}

Ref params_to_py(const cg::Params& params) {
  Ref dict = check(PyDict_New());
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const auto p = static_cast<cg::P>(i);
    set_item(dict.get(), cg::kParams[i].key, param_value_to_py(params, p));
  }
  return dict;
}

// Range bounds: integers for Int parameters, floats otherwise.
static Ref bound_to_py(const cg::ParamDecl& d, float v) {
  if (d.kind == cg::Kind::Int) return check(PyLong_FromLongLong(static_cast<long long>(v)));
  return float_to_py(v);
}

Ref declaration_to_py(cg::P p) {
  const cg::ParamDecl& d = cg::kParams[p];
  static const cg::Params defaults;
  Ref dict = check(PyDict_New());
  set_item(dict.get(), "name", str_to_py(d.key));
  set_item(dict.get(), "label", str_to_py(d.label));
  set_item(dict.get(), "group", str_to_py(d.group));
  set_item(dict.get(), "kind", str_to_py(cg::kind_name(d.kind)));
  set_item(dict.get(), "count", check(PyLong_FromLong(cg::component_count(d.kind))));
  set_item(dict.get(), "default", param_value_to_py(defaults, p));
  set_item(dict.get(), "min", bound_to_py(d, d.min));
  set_item(dict.get(), "max", bound_to_py(d, d.max));
  set_item(dict.get(), "soft_min", bound_to_py(d, d.soft_min));
  set_item(dict.get(), "soft_max", bound_to_py(d, d.soft_max));
  Ref lo = float_to_py(d.map_lo), hi = float_to_py(d.map_hi);
  set_item(dict.get(), "map", check(PyTuple_Pack(2, lo.get(), hi.get())));
  set_item(dict.get(), "unit", str_to_py(d.unit));
  set_item(dict.get(), "help", str_to_py(d.help));
  return dict;
}

// One component as float32. Range, finiteness and integrality are checked by
// cg::Params::set on the float32 value, exactly as for parameter files (so the
// declared min, printed as 0.05, is accepted when passed as 0.05).
static float component_from_py(PyObject* o, const std::string& expect) {
  const double v = number_arg(o, expect.c_str());
  if (std::isfinite(v) && std::fabs(v) > static_cast<double>(FLT_MAX))
    throw cg::ParamError(expect + "; got " + repr(o));  // would become Inf as float32
  return static_cast<float>(v);
}

static void apply_value(cg::Params& params, cg::P p, PyObject* value) {
  const cg::ParamDecl& d = cg::kParams[p];
  const int n = cg::component_count(d.kind);
  const std::string expect = "parameter '" + std::string(d.key) + "' must be " + cg::describe_range(d);
  if (n == 1) {
    const float f = component_from_py(value, expect);
    params.set(p, &f, 1);
    return;
  }
  if (PyUnicode_Check(value) || PyBytes_Check(value) || !PySequence_Check(value))
    raise(PyExc_TypeError, expect + got(value));
  const Py_ssize_t size = PySequence_Size(value);
  if (size < 0) throw PyErrorSet{};
  if (size != n) throw cg::ParamError(expect + "; got " + std::to_string(size) + " value(s)");
  std::vector<float> values(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) {
    Ref item = check(PySequence_GetItem(value, c));
    values[static_cast<std::size_t>(c)] = component_from_py(item.get(), expect);
  }
  params.set(p, values.data(), n);
}

static std::string preset_names() {
  std::string names;
  for (const cg::Preset& preset : cg::presets()) names += (names.empty() ? "" : ", ") + preset.name;
  return names;
}

cg::Params params_from_py(PyObject* obj) {
  cg::Params params;
  if (obj == Py_None) return params;
  if (!PyDict_Check(obj)) raise(PyExc_TypeError, "params must be a dict keyed by parameter names" + got(obj));
  // Iterate over a copy: converting a value may run arbitrary Python code.
  Ref dict = check(PyDict_Copy(obj));
  Ref preset_key = str_to_py("preset");
  PyObject* preset = PyDict_GetItemWithError(dict.get(), preset_key.get());  // borrowed
  if (!preset && PyErr_Occurred()) throw PyErrorSet{};
  if (preset) {
    if (!PyUnicode_Check(preset))
      raise(PyExc_TypeError, "'preset' must be a preset name (" + preset_names() + ")" + got(preset));
    const char* name = PyUnicode_AsUTF8AndSize(preset, nullptr);
    if (!name) throw PyErrorSet{};
    const cg::Preset* found = cg::find_preset(name);
    if (!found)
      throw cg::ParamError("unknown preset '" + clip(name) + "' (known: " + preset_names() + ")" +
                           cg::did_you_mean(name, cg::preset_names()));
    params = found->params;
  }
  Py_ssize_t pos = 0;
  PyObject *key = nullptr, *value = nullptr;  // borrowed from `dict`, which we hold
  while (PyDict_Next(dict.get(), &pos, &key, &value)) {
    if (!PyUnicode_Check(key)) raise(PyExc_TypeError, "parameter names must be str" + got(key));
    Py_ssize_t size = 0;
    const char* name = PyUnicode_AsUTF8AndSize(key, &size);
    if (!name) throw PyErrorSet{};
    const std::string_view k(name, static_cast<std::size_t>(size));
    if (k == "preset") continue;
    const auto p = cg::find_param(k);
    if (!p)
      throw cg::ParamError("unknown parameter '" + clip(k) + "'" + cg::did_you_mean(k, cg::param_keys()) +
                           " (see cloudgen_native.parameters())");
    apply_value(params, *p, value);
  }
  return params;
}

}  // namespace cgpy
