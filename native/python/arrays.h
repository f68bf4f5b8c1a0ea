// arrays.h — arrays in and out of cloudgen_native without NumPy's C headers.
//
// Input points come through the buffer protocol (float32/float64, any
// strides) or, for anything else, numpy.asarray(points, dtype=numpy.float32)
// imported at run time. Output arrays are numpy.empty(..., dtype=float32),
// filled through their buffer.
#pragma once

#include <cstddef>
#include <vector>

#include "convert.h"

namespace cgpy {

// A held Py_buffer, released on scope exit. While it is alive the exporter
// keeps the memory valid, so it may be read or written with the GIL released.
class Buffer {
 public:
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() {
    if (held_) PyBuffer_Release(&view_);
  }
  // Returns false (with no Python error set) when `obj` cannot export with `flags`.
  bool acquire(PyObject* obj, int flags);
  Py_buffer& view() { return view_; }

 private:
  Py_buffer view_{};
  bool held_ = false;
};

// Points of shape (N, 3) as a contiguous x, y, z float array (3N values).
// Raises ValueError naming the expected shape, TypeError for non-numeric input.
std::vector<float> points_from_py(PyObject* points);

// A new float32 numpy array of the given shape (1 or 2 dimensions) and its
// writable, C-contiguous buffer.
struct OutputArray {
  Ref array;
  Buffer buffer;
  float* data() { return static_cast<float*>(buffer.view().buf); }
};
void new_float32_array(OutputArray& out, Py_ssize_t rows, Py_ssize_t columns = -1);

}  // namespace cgpy
