// io/image_format.h — what a cross-section image file is, without the library
// that writes it (the CLI links this; OpenImageIO lives in the image plugin,
// see image_plugin.h).
//
// A slice (row-major floats, row 0 at the top, see cg::slice) is written as
//   .png  8-bit grey for the eye: level = round(255 · (1 − exp(−density / S)))
//         (0 = empty, 255 = opaque; the mapping is monotone and saturates
//         smoothly, so thin and dense regions both stay visible). S is the
//         display scale: `cloudgen preview` uses cg::slice_display_scale(peak)
//         = max(peak / 3, 0.001) (cloudgen/grid.h) unless told --png-scale; the
//         file names S in cloudgen:png_scale and cloudgen:mapping.
//   .exr  32-bit float, one channel "Y" holding the density itself, with
//         metadata cloudgen:params (JSON), cloudgen:axis, cloudgen:offset,
//         cloudgen:version (PNG gets the same entries as text).
// The format follows the extension (case-insensitive); anything else is
// refused by the caller with a message naming --output.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace cgio {

enum class ImageFormat { Png, Exr };

// The format for a file name by its extension, or nothing.
std::optional<ImageFormat> image_format_for(const std::string& path);

// The documented PNG display mapping; scale (S) finite and > 0 (write_slice checks it).
float png_display(float density, float scale);       // 1 - exp(-density / scale), in [0, 1)
std::uint8_t png_level(float density, float scale);  // round(255 · png_display)

struct SliceMeta {
  std::string params_json;
  char axis = 'z';
  float offset = 0.5f;
  float png_scale = 4.0f;  // S of the PNG mapping (> 0, finite; 4: the fixed S before it was recorded)
};

}  // namespace cgio
