// io/image_io.h — cross-section images through OpenImageIO.
//
// A slice (row-major floats, row 0 at the top, see cg::slice) is written as
//   .png  8-bit grey for the eye: level = round(255 · (1 − exp(−density / 4)))
//         (0 = empty, 255 = opaque; the mapping is monotone and saturates
//         smoothly, so thin and dense regions both stay visible)
//   .exr  32-bit float, one channel "Y" holding the density itself, with
//         metadata cloudgen:params (JSON), cloudgen:axis, cloudgen:offset,
//         cloudgen:version (PNG gets the same entries as text).
// The format follows the extension (case-insensitive); anything else is
// refused by the caller with a message naming --output.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace cgio {

enum class ImageFormat { Png, Exr };

// The format for a file name by its extension, or nothing.
std::optional<ImageFormat> image_format_for(const std::string& path);

// The documented PNG display mapping.
float png_display(float density);       // 1 - exp(-density / 4), in [0, 1)
std::uint8_t png_level(float density);  // round(255 · png_display)

struct SliceMeta {
  std::string params_json;
  char axis = 'z';
  float offset = 0.5f;
};

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
