// params.cpp — the parameter table (expanded from param_list.h) and validation.
#include "cloudgen/params.h"

#include "cloudgen/names.h"

#include <charconv>
#include <cmath>
#include <string>

namespace cg {

// Default height curve (Shape Gradient, mode 1): a cumulus profile — a flat
// base that widens within the first eighth of the height, the widest point at
// a quarter, then a dome tapering to the top. Values are squared radii.
const float kDefaultCurve[CG_CURVE_POINTS] = {0.00f, 0.70f, 0.85f, 0.90f, 0.90f, 0.87f, 0.82f, 0.75f, 0.67f,
                                              0.58f, 0.48f, 0.38f, 0.28f, 0.19f, 0.11f, 0.04f, 0.00f};

// One row of param_list.h per entry, in the enum's order (the same rows make the enum).
#define CG_PARAM_UNPAREN(...) __VA_ARGS__
#define CG_PARAM(ENUM, key, label, group, kind, defaults, min, max, soft_min, soft_max, map_lo, map_hi, unit, help) \
  {key,    label,  group, Kind::kind, {CG_PARAM_UNPAREN defaults}, min, max, soft_min, soft_max,                    \
   map_lo, map_hi, unit,  help},
const ParamDecl kParams[PARAM_COUNT] = {
#include "cloudgen/param_list.h"
};
#undef CG_PARAM
#undef CG_PARAM_UNPAREN

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::Float:
      return "float";
    case Kind::Int:
      return "int";
    case Kind::Vector:
      return "vector";
    case Kind::Curve:
      return "curve";
  }
  return "?";
}

int slot_of(P p) {
  int s = 0;
  for (int i = 0; i < p; ++i) s += component_count(kParams[i].kind);
  return s;
}

int slot_count() { return slot_of(PARAM_COUNT); }

std::vector<std::string> param_keys() {
  std::vector<std::string> keys;
  for (const ParamDecl& d : kParams) keys.push_back(d.key);
  return keys;
}

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
    case Kind::Float:
      return "a number in " + range;
    case Kind::Int:
      return "an integer in " + range;
    case Kind::Vector:
      return "3 numbers, each in " + range;
    case Kind::Curve:
      return std::to_string(CG_CURVE_POINTS) + " numbers, each in " + range;
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
  if (!p)
    throw ParamError("unknown parameter '" + std::string(key.substr(0, 100)) + "'" + did_you_mean(key, param_keys()) +
                     " (see `cloudgen params`)");
  set(*p, components, count);
}

}  // namespace cg
