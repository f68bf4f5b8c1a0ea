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

// Material settings of a preset (its "material" object): suggestions for the
// volume shader, not part of the density model. Known keys, each optional:
//   "anisotropy"  Henyey-Greenstein g of the Principled Volume, [-1, 1]
//   "color"       RGB scattering albedo, three numbers in [0, 1]
//   "step_rate"   Cycles volume step rate of the material, [0.01, 100]
struct MaterialValue {
  std::string key;
  std::vector<double> values;  // one for a number, three for "color"
};

struct Preset {
  std::string name;
  std::string description;
  Params params;
  std::vector<MaterialValue> material;  // in the data file's key order
  std::string material_json;            // the "material" object as compact JSON ("{}" when absent)
};

// The material keys a preset may set.
const std::vector<std::string>& material_keys();

// All presets, parsed once from the data file compiled in (native/presets/clouds.json).
const std::vector<Preset>& presets();
// Parse a presets file's text (an object: name -> {"description", "params",
// "material"}). Throws ParamError naming the preset and key of the first bad
// value (unknown parameter or material key, non-number, out of range).
std::vector<Preset> parse_presets(std::string_view text);
// nullptr when there is no such preset.
const Preset* find_preset(std::string_view name);  // ignoring case ("Cumulus")
std::vector<std::string> preset_names();           // in order, for messages
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

// Version of the CLI's machine-readable output (`--json`, docs/cli_protocol.md).
// Bumped only when an event loses a field or a field changes its meaning.
inline constexpr int kProtocolVersion = 1;

}  // namespace cg
