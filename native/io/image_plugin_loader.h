// io/image_plugin_loader.h — the CLI's side of the image plugin (image_plugin.h).
#pragma once

#include <string>
#include <vector>

#include "io/image_format.h"

namespace cgio {

// <directory of the running executable>/../lib/cloudgen_image.so
std::string image_plugin_path();

// Loads the plugin once (later calls return at once). Throws IoError naming
// the path when it is missing, cannot be loaded or belongs to another build.
void load_image_plugin();

// write_slice (image_io.h) through the plugin; loads it first. Throws IoError.
void write_slice_with_plugin(const std::string& path, ImageFormat format, const std::vector<float>& values, int width,
                             int height, const SliceMeta& meta);

}  // namespace cgio
