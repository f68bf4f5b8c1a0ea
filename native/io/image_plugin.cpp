// io/image_plugin.cpp — the image plugin's two entry points (image_plugin.h),
// around write_slice (image_io.cpp, OpenImageIO).
#include "io/image_plugin.h"

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cloudgen/param_io.h"
#include "io/atomic_file.h"
#include "io/image_io.h"

namespace {

std::string plugin_id() { return "cloudgen-image " + std::to_string(CLOUDGEN_IMAGE_PLUGIN_ABI) + " " + cg::version(); }

}  // namespace

extern "C" {

__attribute__((visibility("default"))) const char* cloudgen_image_plugin_id(void) {
  static const std::string id = plugin_id();
  return id.c_str();
}

__attribute__((visibility("default"))) int cloudgen_image_write_slice(const CloudgenImageSlice* s, char* error,
                                                                      std::size_t error_size) {
  try {
    if (!s || !s->path || !s->values || !s->params_json || s->width < 1 || s->height < 1 ||
        (s->format != 0 && s->format != 1))
      throw cgio::IoError("image plugin: malformed request");
    const std::size_t n = std::size_t(s->width) * std::size_t(s->height);
    const std::vector<float> values(s->values, s->values + n);
    const cgio::SliceMeta meta{s->params_json, s->axis, s->offset, s->png_scale};
    cgio::write_slice(s->path, s->format == 0 ? cgio::ImageFormat::Png : cgio::ImageFormat::Exr, values, s->width,
                      s->height, meta);
    return 0;
  } catch (const std::exception& e) {
    if (error && error_size) std::snprintf(error, error_size, "%s", e.what());
  } catch (...) {
    if (error && error_size) std::snprintf(error, error_size, "image plugin: unknown error");
  }
  return 1;
}

}  // extern "C"
