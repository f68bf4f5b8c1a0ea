// io/image_plugin.h — the C interface between the CLI and its image plugin.
//
// Only `cloudgen preview` writes images, and OpenImageIO pulls in about 250
// shared libraries (codecs, OpenCV, ffmpeg, ...) whose loading and symbol
// relocation cost every run of the CLI ~0.1 s before main(). So OpenImageIO
// lives in a plugin, <dir of the cloudgen executable>/../lib/cloudgen_image.so
// (found through /proc/self/exe), loaded with dlopen() by the first preview
// and by nothing else. The interface is plain C so no C++ exception or
// library object crosses it; the plugin names the cloudgen version and the
// interface revision it was built for, and the CLI refuses any other.
#pragma once

#include <cstddef>

extern "C" {

// Raised whenever CloudgenImageSlice or a function's meaning changes.
#define CLOUDGEN_IMAGE_PLUGIN_ABI 2

struct CloudgenImageSlice {
  const char* path;     // the file to write (a temporary name; see atomic_file.h)
  int format;           // 0 = PNG, 1 = EXR (cgio::ImageFormat)
  const float* values;  // width × height densities, row-major, row 0 at the top
  int width, height;
  const char* params_json;  // cg::params_to_json of the parameters
  char axis;                // 'x', 'y' or 'z'
  float offset;
  float png_scale;  // S of the PNG mapping 1 − exp(−density / S) (ABI 2)
};

// "cloudgen-image <ABI> <cloudgen version>": the host loads nothing else.
typedef const char* (*CloudgenImagePluginIdFn)(void);
// Writes the slice; returns 0, or 1 with a one-line message in `error`
// (NUL-terminated, cut to error_size bytes).
typedef int (*CloudgenWriteSliceFn)(const CloudgenImageSlice* slice, char* error, std::size_t error_size);

}  // extern "C"

#define CLOUDGEN_IMAGE_PLUGIN_ID_SYMBOL "cloudgen_image_plugin_id"
#define CLOUDGEN_WRITE_SLICE_SYMBOL "cloudgen_image_write_slice"
