// arrays.cpp — points in (buffer protocol or numpy.asarray), float32 arrays out.
#include "arrays.h"

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace cgpy {

bool Buffer::acquire(PyObject* obj, int flags) {
  if (held_) {
    PyBuffer_Release(&view_);
    held_ = false;
  }
  if (PyObject_GetBuffer(obj, &view_, flags) != 0) {
    PyErr_Clear();
    return false;
  }
  held_ = true;
  return true;
}

static Ref import_numpy() { return check(PyImport_ImportModule("numpy")); }

static const char* kPointsExpect = "points must be an array of shape (N, 3)";

// The element type of a buffer when we can read it directly: 'f' or 'd' in
// native byte order, else 0 (numpy converts it for us).
static char native_float_format(const Py_buffer& v) {
  const char* f = v.format ? v.format : "B";
  if (*f == '@' || *f == '=' || *f == '<') {
    if (*f == '<') {
      const unsigned probe = 1;
      unsigned char first = 0;
      std::memcpy(&first, &probe, 1);
      if (first != 1) return 0;  // big-endian host: '<' is not native
    }
    ++f;
  }
  if (f[0] == 'f' && f[1] == '\0' && v.itemsize == 4) return 'f';
  if (f[0] == 'd' && f[1] == '\0' && v.itemsize == 8) return 'd';
  return 0;
}

static std::string shape_text(const Py_buffer& v) {
  std::string s = "(";
  for (int i = 0; i < v.ndim; ++i) s += (i ? ", " : "") + std::to_string(v.shape[i]);
  if (v.ndim == 1) s += ",";
  return s + ")";
}

// Copies a validated (N, 3) float32/float64 buffer with any strides.
static std::vector<float> copy_points(const Py_buffer& v, char format) {
  const Py_ssize_t n = v.shape[0];
  std::vector<float> out(static_cast<std::size_t>(n) * 3);
  const char* base = static_cast<const char*>(v.buf);
  for (Py_ssize_t i = 0; i < n; ++i)
    for (Py_ssize_t c = 0; c < 3; ++c) {
      const char* item = base + i * v.strides[0] + c * v.strides[1];
      float value;
      if (format == 'f') {
        std::memcpy(&value, item, sizeof value);
      } else {
        double d;
        std::memcpy(&d, item, sizeof d);
        value = static_cast<float>(d);
      }
      out[static_cast<std::size_t>(i * 3 + c)] = value;
    }
  return out;
}

// Refuses, before any copy or conversion, more points than half of this
// machine's memory holds at 16 bytes a point (the float32 copy and the
// result): a broadcast view of 10^9 points once took 16 GB and minutes.
static void check_point_count(Py_ssize_t n) {
  const double pages = double(::sysconf(_SC_PHYS_PAGES)), page = double(::sysconf(_SC_PAGE_SIZE));
  const double budget = pages > 0 && page > 0 ? pages * page / 2.0 : 8.0 * double(1ull << 30);
  if (double(n) * 16.0 > budget) {
    char msg[300];
    std::snprintf(msg, sizeof msg,
                  "%s: %lld points need %.3g GiB (a float32 copy and the result), more than half "
                  "of this machine's memory (%.3g GiB); evaluate them in chunks",
                  kPointsExpect, (long long)n, double(n) * 16.0 / double(1ull << 30), budget / double(1ull << 30));
    raise(PyExc_MemoryError, msg);
  }
}

std::vector<float> points_from_py(PyObject* points) {
  Buffer buffer;
  char format = 0;
  Ref converted;
  if (PyObject_CheckBuffer(points) && buffer.acquire(points, PyBUF_RECORDS_RO)) {
    format = native_float_format(buffer.view());
    if (buffer.view().ndim == 2 && buffer.view().shape[1] == 3) check_point_count(buffer.view().shape[0]);
  }
  if (!format) {
    // Nested sequences, integer or half arrays, foreign byte order: let numpy convert.
    Ref numpy = import_numpy();
    PyObject* array = PyObject_CallMethod(numpy.get(), "asarray", "Os", points, "float32");
    if (!array) {
      if (PyErr_ExceptionMatches(PyExc_ValueError) || PyErr_ExceptionMatches(PyExc_TypeError)) {
        PyErr_Clear();
        raise(PyExc_ValueError, std::string(kPointsExpect) + " of numbers; got " + type_name(points) +
                                    " that numpy cannot convert to float32");
      }
      throw PyErrorSet{};
    }
    converted = Ref(array);
    if (!buffer.acquire(converted.get(), PyBUF_RECORDS_RO))
      raise(PyExc_TypeError, std::string(kPointsExpect) + "; got " + type_name(points));
    format = native_float_format(buffer.view());
    if (!format) raise(PyExc_TypeError, std::string(kPointsExpect) + "; numpy did not give float32");
  }
  const Py_buffer& v = buffer.view();
  if (v.ndim != 2 || v.shape[1] != 3)
    raise(PyExc_ValueError, std::string(kPointsExpect) + "; got shape " + shape_text(v));
  check_point_count(v.shape[0]);
  return copy_points(v, format);
}

void new_float32_array(OutputArray& out, Py_ssize_t rows, Py_ssize_t columns) {
  Ref numpy = import_numpy();
  out.array = columns < 0 ? check(PyObject_CallMethod(numpy.get(), "empty", "(n)s", rows, "float32"))
                          : check(PyObject_CallMethod(numpy.get(), "empty", "(nn)s", rows, columns, "float32"));
  if (!out.buffer.acquire(out.array.get(), PyBUF_CONTIG | PyBUF_FORMAT) ||
      native_float_format(out.buffer.view()) != 'f')
    raise(PyExc_RuntimeError, "cloudgen_native: numpy.empty(dtype=float32) gave no writable float32 buffer");
}

}  // namespace cgpy
