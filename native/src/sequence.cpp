// sequence.cpp — per-frame parameter files.
#include "cloudgen/sequence.h"

#include <cmath>
#include <set>
#include <string>

#include "cloudgen/param_io.h"
#include "json_limits.h"

namespace cg {

using nlohmann::json;

std::vector<SequenceFrame> parse_sequence(std::string_view text, std::string_view origin_view) {
  const std::string origin(origin_view);
  const json doc = parse_json_limited(text, origin, kSequenceFileLimits);
  const std::string shape = ": expected {\"frames\": [{\"frame\": N, \"params\": {...}}, ...]} with at least one frame";
  if (!doc.is_object()) throw ParamError(origin + shape);
  for (const auto& [key, value] : doc.items())
    if (key != "frames" && key != "fps") throw ParamError(origin + ": unknown key '" + brief_text(key) + "'");
  const auto frames = doc.find("frames");
  if (frames == doc.end() || !frames->is_array() || frames->empty()) throw ParamError(origin + shape);
  if (const auto fps = doc.find("fps"); fps != doc.end()) {
    if (!fps->is_number() || !(fps->get<double>() > 0.0 && fps->get<double>() <= 1000.0))
      throw ParamError(origin + ": 'fps' must be a number in (0, 1000]; got " + brief(*fps));
  }
  if (std::ptrdiff_t(frames->size()) > kMaxSequenceFrames)
    throw ParamError(origin + ": " + std::to_string(frames->size()) + " frames; at most " +
                     std::to_string(kMaxSequenceFrames) + " in one sequence file");
  std::vector<SequenceFrame> out;
  std::set<long long> seen;
  for (const json& f : *frames) {
    if (!f.is_object() || !f.contains("frame") || !f["frame"].is_number_integer() || !f.contains("params") ||
        !f["params"].is_object())
      throw ParamError(origin + ": every entry needs an integer \"frame\" and a \"params\" object; got " + brief(f));
    for (const auto& [key, value] : f.items())
      if (key != "frame" && key != "params")
        throw ParamError(origin + ": unknown key '" + brief_text(key) + "' in a frame entry (known: frame, params)");
    // Unsigned integers above INT64_MAX are is_number_integer too: compared as unsigned first.
    const json& number = f["frame"];
    const bool in_range = number.is_number_unsigned()
                              ? number.get<unsigned long long>() <= kMaxFrameNumber
                              : number.get<long long>() >= 0 && number.get<long long>() <= kMaxFrameNumber;
    if (!in_range)
      throw ParamError(origin + ": frame numbers must be in [0, " + std::to_string(kMaxFrameNumber) + "]; got " +
                       brief(number));
    const long long n = number.get<long long>();
    if (!seen.insert(n).second) throw ParamError(origin + ": frame " + std::to_string(n) + " is listed twice");
    out.push_back({n, params_from_value(f["params"], origin + " (frame " + std::to_string(n) + ")")});
  }
  return out;
}

}  // namespace cg
