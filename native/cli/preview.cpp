// cli/preview.cpp — `cloudgen preview`: the 2D cross-section image.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "cli/events.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/param_io.h"
#include "io/atomic_file.h"
#include "io/image_format.h"
#include "io/image_plugin_loader.h"

namespace cli {

namespace {

constexpr int kMaxImageSide = 16384;

const char* const kPreviewHelp =
    "usage: cloudgen preview (--preset NAME | --params FILE.json) --axis x|y|z --offset O\n"
    "                        --size W[xH] --output FILE.png|FILE.exr [--png-scale S|auto] [--lod]\n"
    "                        [--time T] [--threads N] [--json]\n"
    "\n"
    "Writes the 2D cross-section of the density through the cloud box, the plane\n"
    "perpendicular to --axis at --offset (a generated box coordinate in [0, 1],\n"
    "0.5 = the centre). Image axes: axis x → columns +y, rows z; axis y → columns\n"
    "+x, rows z; axis z → columns +x, rows y; the top row is the largest coordinate.\n"
    "\n"
    "  --axis x|y|z        the axis the plane is perpendicular to\n"
    "  --offset O          plane position in [0, 1] (default 0.5)\n"
    "  --size W[xH]        image size in pixels, each in [1, 16384] (default 256); H\n"
    "                      defaults to W × the aspect of the box face\n"
    "  --output FILE       .png: 8-bit grey for the eye, level = round(255·(1 − exp(−density/S)))\n"
    "                      .exr: 32-bit float channel Y = density, with metadata\n"
    "                      cloudgen:params (JSON), cloudgen:axis, cloudgen:offset, cloudgen:version\n"
    "  --png-scale S|auto  the PNG's display scale S in (0, 1e6]; auto (default) = max(peak/3, 0.001):\n"
    "                      the slice's peak at 95 % grey; the PNG names S in cloudgen:png_scale\n"
    "  --lod               limit noise octaves to the pixel footprint (default: all octaves)\n"
    "  --time T            overrides the `time` parameter (seconds)\n"
    "  --threads N         worker threads (default 0 = one per core)\n"
    "  --json              machine-readable output: one `wrote` (or `error`) JSON line\n"
    "\n"
    "The file appears atomically (temporary file + rename).\n"
    "Exit codes: 0 ok, 1 I/O failure, 2 bad argument, 130 cancelled.\n";

}  // namespace

int cmd_preview(const std::vector<std::string>& argv) {
  if (std::find(argv.begin(), argv.end(), "--json") != argv.end()) set_output_mode(OutputMode::Json);
  Args a("preview", argv,
         {{"--preset", true},
          {"--params", true},
          {"--axis", true},
          {"--offset", true},
          {"--size", true},
          {"--output", true},
          {"--png-scale", true},
          {"--lod", false},
          {"--time", true},
          {"--threads", true},
          {"--quiet", false},
          {"--json", false}});
  if (a.help()) return std::cout << kPreviewHelp, kExitOk;
  if (!a.positional().empty()) throw UsageError("preview: unexpected argument '" + a.positional()[0] + "'");

  std::string preset;
  cg::Params params = load_params(a, preset);
  if (a.has("--time")) set_time(params, a.number("--time", -1.0e6, 1.0e6), "--time");
  cg::SliceSpec s;
  const std::string axis = a.text("--axis");
  if (axis != "x" && axis != "y" && axis != "z") throw UsageError("--axis must be x, y or z; got '" + axis + "'");
  s.axis = axis[0] - 'x';
  s.offset = a.has("--offset") ? static_cast<float>(a.number("--offset", 0.0, 1.0)) : 0.5f;
  s.lod = a.has("--lod");
  if (a.has("--threads")) s.threads = static_cast<int>(a.integer("--threads", 0, 1024));
  const std::string output = a.text("--output");
  const auto format = cgio::image_format_for(output);
  if (!format) throw UsageError("--output '" + output + "' must name a .png or .exr file");
  const std::string png_scale = a.get("--png-scale").value_or("auto");
  const bool auto_scale = png_scale == "auto";
  const auto parsed_scale = auto_scale ? std::optional<double>(0.0) : parse_number(png_scale);
  if (!parsed_scale || (!auto_scale && !(*parsed_scale > 0.0 && *parsed_scale <= 1.0e6)))
    throw UsageError("--png-scale must be auto or a finite number in (0, 1e6]; got '" + png_scale + "'");
  const float fixed_scale = static_cast<float>(*parsed_scale);

  const cg::Model model = cg::prepare(params);
  const std::string size = a.get("--size").value_or("256");
  const auto x = size.find_first_of("xX");
  const std::string bad_size =
      "--size must be W or WxH with integers in [1, " + std::to_string(kMaxImageSide) + "]; got '" + size + "'";
  const auto w = parse_integer(size.substr(0, x));
  if (!w || *w < 1 || *w > kMaxImageSide) throw UsageError(bad_size);
  s.width = static_cast<int>(*w);
  if (x != std::string::npos) {
    const auto h = parse_integer(size.substr(x + 1));
    if (!h || *h < 1 || *h > kMaxImageSide) throw UsageError(bad_size);
    s.height = static_cast<int>(*h);
  } else {
    int ca, ra;
    cg::slice_axes(s.axis, ca, ra);
    const double aspect = double(model.box[ra]) / double(model.box[ca]);
    s.height = static_cast<int>(std::clamp(std::lround(double(s.width) * aspect), 1L, long(kMaxImageSide)));
  }
  cgio::check_output_path(output);
  cgio::load_image_plugin();               // OpenImageIO: before any work, so a missing plugin fails at once
  cgio::remove_stale_temporaries(output);  // left by a killed run

  const auto t0 = std::chrono::steady_clock::now();
  cgio::AtomicFile file(output);
  const std::vector<float> values = cg::slice(model, s);
  if (cancel_requested()) throw cg::Cancelled();
  cgio::SliceMeta meta;
  meta.params_json = cg::params_to_json(params);
  meta.axis = axis[0];
  meta.offset = s.offset;
  const float peak = values.empty() ? 0.0f : *std::max_element(values.begin(), values.end());
  meta.png_scale = auto_scale ? cg::slice_display_scale(peak) : fixed_scale;
  file.write_with(
      [&](const std::string& tmp) { cgio::write_slice_with_plugin(tmp, *format, values, s.width, s.height, meta); });
  if (cancel_requested()) throw cg::Cancelled();
  file.commit();
  const double seconds = seconds_since(t0);
  char line[200];
  char scale_note[48] = "";
  if (*format == cgio::ImageFormat::Png) std::snprintf(scale_note, sizeof scale_note, ", PNG scale %g", meta.png_scale);
  std::snprintf(line, sizeof line, " (%dx%d, axis %s at %g, max density %g%s, %.2f s)", s.width, s.height, axis.c_str(),
                s.offset, peak, scale_note, seconds);
  emit("wrote",
       {{"path", output},
        {"size", {s.width, s.height}},
        {"axis", axis},
        {"offset", s.offset},
        {"max_density", peak},
        {"png_scale", *format == cgio::ImageFormat::Png ? Fields(meta.png_scale) : Fields()},
        {"bytes", cgio::file_size(output)},
        {"seconds", seconds}},
       "wrote " + output + line);
  return kExitOk;
}

}  // namespace cli
