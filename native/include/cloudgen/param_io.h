// cloudgen/param_io.h — presets and parameter files (JSON).
//
// A parameter file is one JSON object. An optional "preset" names the cloud
// type it starts from; every other key is a declared parameter (see
// `cloudgen params`), a number for float/int parameters and a list for
// vectors and the shape curve. Missing keys keep their defaults; unknown keys,
// wrong types and values outside the declared range are refused with a
// ParamError naming the key.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "cloudgen/params.h"

namespace cg {

struct Preset {
  std::string name;
  std::string description;
  Params params;
};

// All presets, parsed once from the data file compiled in (native/presets/clouds.json).
const std::vector<Preset>& presets();
// nullptr when there is no such preset.
const Preset* find_preset(std::string_view name);
// The raw JSON text of the presets file (for the add-on and the docs).
const char* presets_json();

// Parse a parameter file's text. `origin` names the source in error messages.
Params params_from_json(std::string_view text, std::string_view origin = "parameters");
// Serialise every parameter (used for VDB/EXR metadata and `cloudgen params --defaults`).
std::string params_to_json(const Params& p, int indent = -1);
// The declarations as JSON (name, label, group, kind, default, ranges, unit, help, mapping).
std::string declarations_json(int indent = 2);

// The library version, for metadata.
const char* version();

}  // namespace cg
