// io/image_io.cpp — PNG/EXR slices through OpenImageIO (built into the image plugin and the I/O tests).
#include "io/image_io.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cloudgen/param_io.h"
#include "io/atomic_file.h"

namespace cgio {

void write_slice(const std::string& path, ImageFormat format, const std::vector<float>& values, int width, int height,
                 const SliceMeta& meta) {
  using namespace OIIO;
  if (width < 1 || height < 1 || values.size() != std::size_t(width) * std::size_t(height))
    throw IoError("cannot write '" + path + "': image size does not match its pixels");
  const bool png = format == ImageFormat::Png;
  if (png && !(std::isfinite(meta.png_scale) && meta.png_scale > 0.0f))
    throw IoError("cannot write '" + path + "': the PNG display scale must be finite and > 0");
  auto out = ImageOutput::create(png ? "png" : "openexr");
  if (!out)
    throw IoError("cannot write '" + path + "': OpenImageIO has no " + (png ? "PNG" : "OpenEXR") + " writer (" +
                  OIIO::geterror() + ")");
  ImageSpec spec(width, height, 1, png ? TypeDesc::UINT8 : TypeDesc::FLOAT);
  spec.channelnames = {"Y"};
  spec.attribute("Software", std::string("cloudgen ") + cg::version());
  spec.attribute("cloudgen:params", meta.params_json);
  spec.attribute("cloudgen:axis", std::string(1, meta.axis));
  spec.attribute("cloudgen:version", std::string(cg::version()));
  if (png) {
    spec.attribute("cloudgen:offset", std::to_string(meta.offset));
    char scale[32];
    std::snprintf(scale, sizeof scale, "%.9g", double(meta.png_scale));
    spec.attribute("cloudgen:png_scale", std::string(scale));
    spec.attribute("cloudgen:mapping", std::string("level = round(255 * (1 - exp(-density / ") + scale + ")))");
  } else {
    spec.attribute("cloudgen:offset", meta.offset);
    spec.attribute("compression", "zip");
  }
  if (!out->open(path, spec)) throw IoError("cannot write '" + path + "': " + out->geterror());
  bool ok;
  if (png) {
    std::vector<std::uint8_t> levels(values.size());
    std::transform(values.begin(), values.end(), levels.begin(), [&](float d) { return png_level(d, meta.png_scale); });
    ok = out->write_image(TypeDesc::UINT8, levels.data());
  } else {
    ok = out->write_image(TypeDesc::FLOAT, values.data());
  }
  const std::string err = ok ? "" : out->geterror();
  if (!out->close() || !ok) throw IoError("cannot write '" + path + "': " + (err.empty() ? out->geterror() : err));
}

ImageData read_image(const std::string& path) {
  using namespace OIIO;
  auto in = ImageInput::open(path);
  if (!in) throw IoError("cannot read '" + path + "': " + OIIO::geterror());
  const ImageSpec& spec = in->spec();
  ImageData img;
  img.width = spec.width;
  img.height = spec.height;
  img.channels = spec.nchannels;
  img.format_name = in->format_name();
  img.pixel_type = spec.format.c_str();
  img.channel_names = spec.channelnames;
  for (const ParamValue& p : spec.extra_attribs) img.metadata[p.name().string()] = p.get_string();
  img.pixels.resize(std::size_t(img.width) * img.height * img.channels);
  bool ok;
  if (spec.format == TypeDesc::UINT8) {
    std::vector<std::uint8_t> raw(img.pixels.size());
    ok = in->read_image(0, 0, 0, img.channels, TypeDesc::UINT8, raw.data());
    std::copy(raw.begin(), raw.end(), img.pixels.begin());
  } else {
    ok = in->read_image(0, 0, 0, img.channels, TypeDesc::FLOAT, img.pixels.data());
  }
  if (!ok) throw IoError("cannot read '" + path + "': " + in->geterror());
  in->close();
  return img;
}

}  // namespace cgio
