// io/image_format.cpp — image formats by extension and the PNG display mapping.
#include "io/image_format.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace cgio {

std::optional<ImageFormat> image_format_for(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return std::nullopt;
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == "png") return ImageFormat::Png;
  if (ext == "exr") return ImageFormat::Exr;
  return std::nullopt;
}

float png_display(float density, float scale) {
  const float d = std::isfinite(density) ? std::max(density, 0.0f) : 0.0f;
  return 1.0f - std::exp(-d / scale);
}

std::uint8_t png_level(float density, float scale) {
  const float level = std::round(255.0f * png_display(density, scale));
  return static_cast<std::uint8_t>(std::clamp(level, 0.0f, 255.0f));
}

}  // namespace cgio
