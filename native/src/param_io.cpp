// param_io.cpp — presets and JSON parameter files.
#include "cloudgen/param_io.h"
#include "cloudgen/names.h"

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>

#include "cloudgen_presets_data.h"  // generated: kPresetsJson
#include "cloudgen_version.h"       // generated: kCloudgenVersion
#include "json_limits.h"

namespace cg {

using nlohmann::json;

namespace {

std::string where(std::string_view origin, std::string_view key) {
  return std::string(origin) + ": parameter '" + std::string(key) + "'";
}

void apply_value(Params& params, P p, const json& v, std::string_view origin) {
  const ParamDecl& d = kParams[p];
  const int n = component_count(d.kind);
  std::vector<float> values;
  auto take = [&](const json& x) {
    if (!x.is_number()) throw ParamError(where(origin, d.key) + " must be " + describe_range(d) + "; got " + brief(x));
    const double dv = x.get<double>();
    if (!std::isfinite(dv) || std::fabs(dv) > FLT_MAX)
      throw ParamError(where(origin, d.key) + " must be " + describe_range(d) + "; got " + brief(x));
    values.push_back(static_cast<float>(dv));
  };
  if (n == 1) {
    take(v);
  } else {
    if (!v.is_array())
      throw ParamError(where(origin, d.key) + " must be a list of " + describe_range(d) + "; got " + brief(v));
    for (const json& x : v) take(x);
  }
  try {
    params.set(p, values.data(), static_cast<int>(values.size()));
  } catch (const ParamError& e) {
    throw ParamError(std::string(origin) + ": " + e.message);
  }
}

void apply_object(Params& params, const json& obj, std::string_view origin) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const auto p = find_param(it.key());
    if (!p)
      throw ParamError(std::string(origin) + ": unknown parameter '" + brief_text(it.key()) + "'" +
                       did_you_mean(it.key(), param_keys()) + " (see `cloudgen params`)");
    apply_value(params, *p, it.value(), origin);
  }
}

struct MaterialDecl {
  const char* key;
  int count;
  double min, max;
};

constexpr MaterialDecl kMaterial[] = {
    {"anisotropy", 1, -1.0, 1.0},
    {"color", 3, 0.0, 1.0},
    {"step_rate", 1, 0.01, 100.0},
    {"halo", 1, 0.0, 10.0},  // the 22-degree ice halo's strength, 1 = addon/volume_material.py's HALO_PEAK_PER_SR
    // ice veils: the Fournier-Forand phase's backscatter fraction (addon/volume_material.py's
    // ICE_IOR); Cycles clamps it below 0.5, and at 0 the phase is a delta
    {"backscatter", 1, 0.001, 0.49},
    // ...and the share of their scattering in a wide lobe (volume_material.py's ICE_SIDE_G)
    {"side_scatter", 1, 0.0, 0.5},
};

std::string shortest(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::vector<MaterialValue> parse_material(const json& obj, const std::string& origin) {
  if (!obj.is_object()) throw ParamError(origin + ": 'material' must be an object; got " + brief(obj));
  std::vector<MaterialValue> out;
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const MaterialDecl* decl = nullptr;
    for (const MaterialDecl& d : kMaterial)
      if (it.key() == d.key) decl = &d;
    std::string known;
    for (const MaterialDecl& d : kMaterial) known += (known.empty() ? "" : ", ") + std::string(d.key);
    if (!decl)
      throw ParamError(origin + ": unknown material key '" + brief_text(it.key()) + "' (known: " + known + ")");
    const std::string what = origin + ": material '" + it.key() + "' must be " +
                             (decl->count == 1 ? "a number" : "a list of " + std::to_string(decl->count) + " numbers") +
                             " in [" + shortest(decl->min) + ", " + shortest(decl->max) + "]; got " + brief(it.value());
    MaterialValue value{it.key(), {}};
    const json& v = it.value();
    if (decl->count == 1 ? !v.is_number() : !(v.is_array() && v.size() == static_cast<size_t>(decl->count)))
      throw ParamError(what);
    for (const json& x : decl->count == 1 ? json::array({v}) : v) {
      if (!x.is_number()) throw ParamError(what);
      const double d = x.get<double>();
      if (!(d >= decl->min && d <= decl->max)) throw ParamError(what);  // also NaN
      value.values.push_back(d);
    }
    out.push_back(std::move(value));
  }
  return out;
}

json value_json(const Params& p, P i) {
  const ParamDecl& d = kParams[i];
  const int n = component_count(d.kind);
  if (n == 1) return d.kind == Kind::Int ? json(static_cast<long long>(p.get(i))) : json(p.get(i));
  json arr = json::array();
  for (int c = 0; c < n; ++c) arr.push_back(p.get(i, c));
  return arr;
}

}  // namespace

const std::vector<std::string>& material_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    for (const MaterialDecl& d : kMaterial) k.emplace_back(d.key);
    return k;
  }();
  return keys;
}

std::vector<Preset> parse_presets(std::string_view text) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw ParamError(std::string("presets: not valid JSON (") + json_error_text(e.what()) + ")");
  }
  if (!doc.is_object()) throw ParamError("presets: expected a JSON object of presets");
  std::vector<Preset> out;
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string origin = "preset '" + it.key() + "'";
    const json& entry = it.value();
    if (!entry.is_object()) throw ParamError(origin + ": expected an object");
    for (auto k = entry.begin(); k != entry.end(); ++k)
      if (k.key() != "description" && k.key() != "params" && k.key() != "material")
        throw ParamError(origin + ": unknown key '" + k.key() + "' (known: description, params, material)");
    if (!entry.contains("params") || !entry["params"].is_object())
      throw ParamError(origin + ": 'params' must be an object of parameters");
    Preset preset;
    preset.name = it.key();
    if (entry.contains("description")) {
      if (!entry["description"].is_string()) throw ParamError(origin + ": 'description' must be text");
      preset.description = entry["description"].get<std::string>();
    }
    apply_object(preset.params, entry["params"], origin);
    const json material = entry.value("material", json::object());
    preset.material = parse_material(material, origin);
    preset.material_json = material.dump();
    out.push_back(std::move(preset));
  }
  return out;
}

const char* presets_json() { return kPresetsJson; }
const char* version() { return kCloudgenVersion; }

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = parse_presets(kPresetsJson);
  return all;
}

const Preset* find_preset(std::string_view name) {
  for (const Preset& p : presets())
    if (same_name(p.name, name)) return &p;
  return nullptr;
}

std::vector<std::string> preset_names() {
  std::vector<std::string> names;
  for (const Preset& p : presets()) names.push_back(p.name);
  return names;
}

Params params_from_json(std::string_view text, std::string_view origin) {
  return params_from_value(parse_json_limited(text, std::string(origin), kSmallFileLimits), origin);
}

Params params_from_value(const json& value, std::string_view origin) {
  if (!value.is_object()) throw ParamError(std::string(origin) + ": expected a JSON object of parameters");
  json doc = value;
  Params params;
  if (auto it = doc.find("preset"); it != doc.end()) {
    if (!it->is_string()) throw ParamError(std::string(origin) + ": 'preset' must be a preset name");
    const Preset* preset = find_preset(it->get<std::string>());
    if (!preset)
      throw ParamError(std::string(origin) + ": unknown preset '" + brief_text(it->get<std::string>()) + "'" +
                       did_you_mean(it->get<std::string>(), preset_names()) + " (see `cloudgen presets`)");
    params = preset->params;
    doc.erase(it);
  }
  apply_object(params, doc, origin);
  return params;
}

std::string params_to_json(const Params& p, int indent) {
  json obj = json::object();
  for (int i = 0; i < PARAM_COUNT; ++i) obj[kParams[i].key] = value_json(p, static_cast<P>(i));
  return obj.dump(indent);
}

std::string declarations_json(int indent) {
  const Params defaults;
  json arr = json::array();
  for (int i = 0; i < PARAM_COUNT; ++i) {
    const ParamDecl& d = kParams[i];
    arr.push_back({{"name", d.key},
                   {"label", d.label},
                   {"group", d.group},
                   {"kind", kind_name(d.kind)},
                   {"count", component_count(d.kind)},
                   {"default", value_json(defaults, static_cast<P>(i))},
                   {"min", d.min},
                   {"max", d.max},
                   {"soft_min", d.soft_min},
                   {"soft_max", d.soft_max},
                   {"map", {d.map_lo, d.map_hi}},
                   {"unit", d.unit},
                   {"help", d.help}});
  }
  return arr.dump(indent);
}

}  // namespace cg
