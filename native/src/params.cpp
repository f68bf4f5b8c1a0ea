// params.cpp — the parameter table (the one declaration) and validation.
#include "cloudgen/params.h"

#include <cmath>
#include <charconv>
#include <string>

namespace cg {

// Default height curve (Shape Gradient, mode 1): a cumulus profile — a flat
// base that widens within the first eighth of the height, the widest point at
// a quarter, then a dome tapering to the top. Values are squared radii.
const float kDefaultCurve[CG_CURVE_POINTS] = {0.00f, 0.70f, 0.85f, 0.90f, 0.90f, 0.87f,
                                              0.82f, 0.75f, 0.67f, 0.58f, 0.48f, 0.38f,
                                              0.28f, 0.19f, 0.11f, 0.04f, 0.00f};

// clang-format off
const ParamDecl kParams[PARAM_COUNT] = {
  // key, label, group, kind, default, min, max, soft_min, soft_max, map_lo, map_hi, unit, help
  {"cloud_scale", "Cloud Scale", "Cloud Main", Kind::Float, {0.85f}, 0.05f, 1.0f, 0.05f, 1.0f, 0, 1,
   "fraction of the box", "Size of the cloud inside its box: 1 touches the box faces, smaller values shrink it about the centre."},
  {"density", "Density", "Cloud Main", Kind::Float, {0.5f}, 0.0f, 10.0f, 0.0f, 1.0f, 0, CG_DENSITY_SCALE,
   "slider (x20 per scene unit)", "Density handed to the volume shader: the physical density is 20 x this value x the shape density (about 1 in the cloud's core)."},
  {"distortion", "Distortion", "Cloud Main", Kind::Float, {0.7f}, 0.0f, 2.0f, 0.0f, 1.0f, 0, 1,
   "", "How strongly the Cloud Noise texture distorts the shape (F in eq. 3.4)."},
  {"shape_mode", "Shape Source", "Cloud Main", Kind::Int, {0}, 0, 1, 0, 1, 0, 1,
   "0 exponent, 1 curve", "Where the height profile comes from: 0 the Shape Exponent, 1 the Shape Gradient curve."},
  {"shape_exponent", "Shape Exponent", "Cloud Main", Kind::Float, {0.6f}, 0.05f, 20.0f, 0.1f, 4.0f, 0, 1,
   "", "Height-profile exponent e in S = 1 - (2 h^e - 1)^2: below 1 a flat base and a dome, above 1 a wide top."},
  {"shape_curve", "Shape Gradient", "Cloud Main", Kind::Curve, {0}, 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
   "squared radius", "Height profile as 17 samples at heights 0, 1/16, ..., 1 (used when Shape Source is 1)."},
  {"overall_scale", "Overall Scale", "Cloud Noise", Kind::Float, {1.0f}, 0.01f, 20.0f, 0.1f, 4.0f, 0, 1,
   "", "Scales the whole texture: larger values give smaller, more numerous features."},
  {"worley_influence", "Worley Influence", "Cloud Noise", Kind::Float, {0.8f}, 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
   "", "Weight of the Worley (billow) component."},
  {"worley_clump", "Worley Clump", "Cloud Noise", Kind::Float, {0.5f}, 0.0f, 2.0f, 0.0f, 1.0f, 0, 1,
   "gain", "Gain of the Worley fBm: higher values add smaller billows on the large ones."},
  {"wave", "Wave", "Cloud Noise", Kind::Float, {0.0f}, 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
   "", "Mixes a sine texture into the Worley component for wave-like banding (cirrus)."},
  {"noise_influence", "Noise Influence", "Cloud Noise", Kind::Float, {0.6f}, 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
   "", "Weight of the gradient-noise fBm (fine detail, frayed edges)."},
  {"noise_scale", "Noise Scale", "Cloud Noise", Kind::Float, {1.0f}, 0.01f, 20.0f, 0.1f, 4.0f, 0, 1,
   "", "Extra scale of the gradient-noise fBm relative to the Worley texture."},
  {"noise_detail", "Noise Detail", "Cloud Noise", Kind::Float, {5.0f}, 0.0f, 16.0f, 1.0f, 12.0f, 0, 1,
   "octaves", "Octaves of the gradient-noise fBm; a fractional part fades the last octave in."},
  {"noise_whisp", "Noise Whisp", "Cloud Noise", Kind::Float, {0.5f}, 0.0f, 2.0f, 0.0f, 1.0f, 0, 1,
   "gain", "Gain of the gradient-noise fBm: higher values give wispier, finer detail."},
  {"seed", "Seed", "Cloud Noise", Kind::Int, {0}, 0, 1000000, 0, 1000, 0, 1,
   "", "Variation: a different seed gives a different cloud of the same kind."},
  {"wind_strength", "Wind Strength", "Animation", Kind::Float, {0.0f}, 0.0f, 100.0f, 0.0f, 1.0f, 0, 1,
   "scene units per second", "Speed at which the texture drifts along the wind direction."},
  {"wind_direction", "Wind Direction", "Animation", Kind::Vector, {1.0f, 0.0f, 0.0f}, -1.0f, 1.0f, -1.0f, 1.0f, 0, 1,
   "direction", "Direction of the drift (normalised; zero means no drift)."},
  {"stationary", "Stationary", "Animation", Kind::Float, {1.0f}, 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
   "", "How much the texture follows the object: 1 moves with it, 0 stays fixed in the world."},
  {"time", "Time", "Animation", Kind::Float, {0.0f}, -1.0e6f, 1.0e6f, 0.0f, 250.0f, 0, 1,
   "seconds", "Time in seconds: drives wind drift and evolution."},
  {"evolution", "Evolution", "Animation", Kind::Float, {0.1f}, 0.0f, 10.0f, 0.0f, 1.0f, 0, 1,
   "noise cells per second", "Speed of the shape change that is not drift (the fourth noise dimension)."},
  {"box_size", "Box Size", "Box", Kind::Vector, {2.0f, 2.0f, 2.0f}, 0.001f, 1.0e5f, 0.1f, 100.0f, 0, 1,
   "scene units", "Dimensions of the cloud box (the object's scale included)."},
  {"object_location", "Object Location", "Box", Kind::Vector, {0.0f, 0.0f, 0.0f}, -1.0e7f, 1.0e7f, -100.0f, 100.0f, 0, 1,
   "scene units", "World location of the cloud object (used by Stationary)."},
};
// clang-format on

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::Float: return "float";
    case Kind::Int: return "int";
    case Kind::Vector: return "vector";
    case Kind::Curve: return "curve";
  }
  return "?";
}

int slot_of(P p) {
  int s = 0;
  for (int i = 0; i < p; ++i) s += component_count(kParams[i].kind);
  return s;
}

int slot_count() { return slot_of(PARAM_COUNT); }

std::optional<P> find_param(std::string_view key) {
  for (int i = 0; i < PARAM_COUNT; ++i)
    if (key == kParams[i].key) return static_cast<P>(i);
  return std::nullopt;
}

// Shortest decimal that reads back as the same float (0.05, not 0.0500000007),
// in plain notation (100000, not 1e+05) unless that gets long.
static std::string num(float v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  if (r.ec != std::errc() || r.ptr - buf > 12) r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string describe_range(const ParamDecl& d) {
  std::string range = "[";  // appended piecewise: `"[" + std::string` trips a GCC 12 -Wrestrict false positive
  range += num(d.min);
  range += ", ";
  range += num(d.max);
  range += "]";
  switch (d.kind) {
    case Kind::Float: return "a number in " + range;
    case Kind::Int: return "an integer in " + range;
    case Kind::Vector: return "3 numbers, each in " + range;
    case Kind::Curve: return std::to_string(CG_CURVE_POINTS) + " numbers, each in " + range;
  }
  return range;
}

Params::Params() {
  for (int i = 0; i < PARAM_COUNT; ++i) {
    const ParamDecl& d = kParams[i];
    const int s = slot_of(static_cast<P>(i));
    for (int c = 0; c < component_count(d.kind); ++c)
      values[s + c] = d.kind == Kind::Curve ? kDefaultCurve[c] : d.default_value[c];
  }
}

float Params::physical(P p, int component) const {
  const ParamDecl& d = kParams[p];
  return d.map_lo + (d.map_hi - d.map_lo) * get(p, component);
}

void Params::set(P p, const float* components, int count) {
  const ParamDecl& d = kParams[p];
  const int n = component_count(d.kind);
  const std::string expect = "parameter '" + std::string(d.key) + "' must be " + describe_range(d);
  if (count != n) throw ParamError(expect + "; got " + std::to_string(count) + " value(s)");
  for (int c = 0; c < n; ++c) {
    const float v = components[c];
    if (!std::isfinite(v)) throw ParamError(expect + "; got a non-finite value (NaN or Inf)");
    if (v < d.min || v > d.max) throw ParamError(expect + "; got " + num(v));
    if (d.kind == Kind::Int && std::floor(v) != v) throw ParamError(expect + "; got " + num(v));
  }
  for (int c = 0; c < n; ++c) values[slot_of(p) + c] = components[c];
}

void Params::set(std::string_view key, const float* components, int count) {
  const auto p = find_param(key);
  if (!p) throw ParamError("unknown parameter '" + std::string(key) + "' (see `cloudgen params`)");
  set(*p, components, count);
}

}  // namespace cg
