// io/image_io.h — cross-section images through OpenImageIO: the code of the
// image plugin (image_plugin.h) and of the I/O tests. The CLI itself never
// links OpenImageIO; it calls this through the plugin.
//
// The file formats (PNG display mapping, EXR channel and metadata) are
// described in image_format.h.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "io/image_format.h"

namespace cgio {

// Writes width × height densities to `path` in `format` (the path may carry a
// temporary name; the format does not depend on it). Throws IoError.
void write_slice(const std::string& path, ImageFormat format, const std::vector<float>& values, int width, int height,
                 const SliceMeta& meta);

// An image read back (tests): pixels as floats (PNG levels 0..255 are
// returned as the integer levels, not normalised), metadata as text.
struct ImageData {
  int width = 0, height = 0, channels = 0;
  std::string format_name;  // OIIO's name: "png", "openexr"
  std::string pixel_type;   // e.g. "uint8", "float"
  std::vector<std::string> channel_names;
  std::vector<float> pixels;  // row-major, channels interleaved
  std::map<std::string, std::string> metadata;
};

// Throws IoError.
ImageData read_image(const std::string& path);

}  // namespace cgio
