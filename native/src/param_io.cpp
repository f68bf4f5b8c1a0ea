// param_io.cpp — presets and JSON parameter files.
#include "cloudgen/param_io.h"

#include <cfloat>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>

#include "cloudgen_presets_data.h"  // generated: kPresetsJson
#include "cloudgen_version.h"       // generated: kCloudgenVersion

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
    if (!x.is_number())
      throw ParamError(where(origin, d.key) + " must be " + describe_range(d) + "; got " + x.dump());
    const double dv = x.get<double>();
    if (!std::isfinite(dv) || std::fabs(dv) > FLT_MAX)
      throw ParamError(where(origin, d.key) + " must be " + describe_range(d) + "; got " + x.dump());
    values.push_back(static_cast<float>(dv));
  };
  if (n == 1) {
    take(v);
  } else {
    if (!v.is_array())
      throw ParamError(where(origin, d.key) + " must be a list of " + describe_range(d) + "; got " + v.dump());
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
    if (!p) throw ParamError(std::string(origin) + ": unknown parameter '" + it.key() + "' (see `cloudgen params`)");
    apply_value(params, *p, it.value(), origin);
  }
}

std::vector<Preset> parse_presets() {
  std::vector<Preset> out;
  const json doc = json::parse(kPresetsJson);
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    Preset preset;
    preset.name = it.key();
    preset.description = it.value().value("description", "");
    apply_object(preset.params, it.value().at("params"), "preset '" + preset.name + "'");
    out.push_back(std::move(preset));
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

const char* presets_json() { return kPresetsJson; }
const char* version() { return kCloudgenVersion; }

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = parse_presets();
  return all;
}

const Preset* find_preset(std::string_view name) {
  for (const Preset& p : presets())
    if (p.name == name) return &p;
  return nullptr;
}

Params params_from_json(std::string_view text, std::string_view origin) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // parse errors, and numbers out of range such as 1e999
    throw ParamError(std::string(origin) + ": not valid JSON (" + e.what() + ")");
  }
  if (!doc.is_object()) throw ParamError(std::string(origin) + ": expected a JSON object of parameters");
  Params params;
  if (auto it = doc.find("preset"); it != doc.end()) {
    if (!it->is_string()) throw ParamError(std::string(origin) + ": 'preset' must be a preset name");
    const Preset* preset = find_preset(it->get<std::string>());
    if (!preset) throw ParamError(std::string(origin) + ": unknown preset '" + it->get<std::string>() + "' (see `cloudgen presets`)");
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
    arr.push_back({{"name", d.key},          {"label", d.label},
                   {"group", d.group},       {"kind", kind_name(d.kind)},
                   {"count", component_count(d.kind)},
                   {"default", value_json(defaults, static_cast<P>(i))},
                   {"min", d.min},           {"max", d.max},
                   {"soft_min", d.soft_min}, {"soft_max", d.soft_max},
                   {"map", {d.map_lo, d.map_hi}},
                   {"unit", d.unit},         {"help", d.help}});
  }
  return arr.dump(indent);
}

}  // namespace cg
