// tiers.cpp — parsing and checking the quality tiers data file.
#include "cloudgen/tiers.h"

#include "cloudgen/names.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "cloudgen/params.h"      // ParamError
#include "cloudgen_tiers_data.h"  // generated: kTiersJson

namespace cg {

namespace {

using json = nlohmann::ordered_json;

const json& member(const json& obj, const char* key, const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end()) throw ParamError(where + ": missing '" + key + "'");
  return *it;
}

double number(const json& obj, const char* key, double lo, double hi, const std::string& where) {
  const json& v = member(obj, key, where);
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo || v.get<double>() > hi)
    throw ParamError(where + "." + key + " must be a number in [" + json(lo).dump() + ", " + json(hi).dump() +
                     "]; got " + v.dump());
  return v.get<double>();
}

int integer(const json& obj, const char* key, int lo, int hi, const std::string& where) {
  const double v = number(obj, key, lo, hi, where);
  if (v != std::floor(v)) throw ParamError(where + "." + key + " must be a whole number; got " + json(v).dump());
  return static_cast<int>(v);
}

bool flag(const json& obj, const char* key, const std::string& where) {
  const json& v = member(obj, key, where);
  if (!v.is_boolean()) throw ParamError(where + "." + key + " must be true or false; got " + v.dump());
  return v.get<bool>();
}

const json& section(const json& obj, const char* key, const std::string& where) {
  const json& v = member(obj, key, where);
  if (!v.is_object()) throw ParamError(where + "." + key + " must be an object");
  return v;
}

}  // namespace

std::vector<Tier> parse_tiers(std::string_view text) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw ParamError(std::string("tiers: not valid JSON (") + json_error_text(e.what()) + ")");
  }
  if (!doc.is_object() || doc.empty()) throw ParamError("tiers: expected a non-empty object of tiers");
  std::vector<Tier> out;
  for (const auto& [name, t] : doc.items()) {
    const std::string where = "tier '" + name + "'";
    if (!t.is_object()) throw ParamError(where + ": expected an object");
    Tier tier;
    tier.name = name;
    const json& label = member(t, "label", where);
    const json& description = member(t, "description", where);
    if (!label.is_string() || !description.is_string())
      throw ParamError(where + ": 'label' and 'description' must be strings");
    tier.label = label.get<std::string>();
    tier.description = description.get<std::string>();
    const json& render = section(t, "render", where);
    tier.render_samples = integer(render, "samples", 1, 1 << 24, where + ".render");
    tier.render_step_rate = static_cast<float>(number(render, "step_rate", 0.01, 100.0, where + ".render"));
    const json& bake = section(t, "bake", where);
    tier.bake_resolution = integer(bake, "resolution", 1, 1000000, where + ".bake");
    tier.bake_lod = flag(bake, "lod", where + ".bake");
    tier.bake_tolerance = static_cast<float>(number(bake, "tolerance", 0.0, 1.0e30, where + ".bake"));
    tier.bake_half = flag(bake, "half", where + ".bake");
    if (bake.contains("pixels_per_voxel"))
      tier.bake_pixels_per_voxel =
          static_cast<float>(number(bake, "pixels_per_voxel", kMinPixelsPerVoxel, kMaxPixelsPerVoxel, where + ".bake"));
    const json& preview = section(t, "preview", where);
    tier.preview_size = integer(preview, "size", 1, 16384, where + ".preview");
    if (const auto m = t.find("measured"); m != t.end() && !m->is_object())
      throw ParamError(where + ".measured must be an object");
    out.push_back(std::move(tier));
  }
  return out;
}

const std::vector<Tier>& tiers() {
  static const std::vector<Tier> all = parse_tiers(kTiersJson);
  return all;
}

const Tier* find_tier(std::string_view name) {
  for (const Tier& t : tiers())
    if (same_name(t.name, name)) return &t;
  return nullptr;
}

const char* tiers_json() { return kTiersJson; }

}  // namespace cg
