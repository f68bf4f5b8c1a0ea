// cloudgen/params.h — every user parameter, declared once.
//
// The rows of param_list.h are the single source of truth for names,
// defaults, ranges, units, help texts and slider mappings: they expand into
// the enum P here and into the table kParams in params.cpp. The CLI's parameter files,
// the Python module (parameters()), the OSL metadata and the add-on's sockets
// are fed from it or checked against it by tests.
//
// Values are stored flat in Params::values (a vector parameter takes 3 slots,
// the shape curve CG_CURVE_POINTS). Values are what the user sets (slider
// values); physical() applies the declared mapping where a 0–1 slider stands
// for a wider physical range.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cloudgen/shared/cloud_model.h"

namespace cg {

enum class Kind { Float, Int, Vector, Curve };

const char* kind_name(Kind k);

struct ParamDecl {
  const char* key;    // identifier used in files, dicts and on the command line
  const char* label;  // what the artist sees (the thesis's names)
  const char* group;  // "Cloud Main", "Cloud Noise", "Animation", "Box"
  Kind kind;
  float default_value[3];    // a curve's default is kDefaultCurve
  float min, max;            // hard limits: anything outside is refused at the API boundary
  float soft_min, soft_max;  // slider range
  float map_lo, map_hi;      // physical = map_lo + (map_hi - map_lo) * value (0,1 = identity)
  const char* unit;
  const char* help;
};

// Parameter indices, in declaration order: the first column of param_list.h.
enum P : int {
#define CG_PARAM(ENUM, ...) ENUM,
#include "cloudgen/param_list.h"
#undef CG_PARAM
  PARAM_COUNT
};

extern const ParamDecl kParams[PARAM_COUNT];
extern const float kDefaultCurve[CG_CURVE_POINTS];

constexpr int component_count(Kind k) { return k == Kind::Vector ? 3 : k == Kind::Curve ? CG_CURVE_POINTS : 1; }
int slot_of(P p);                       // first slot of parameter p in Params::values
int slot_count();                       // total number of slots
std::vector<std::string> param_keys();  // every parameter's key, in order (for messages)
std::optional<P> find_param(std::string_view key);

// Error for a bad parameter: what() names the parameter and the accepted range.
struct ParamError : std::exception {
  std::string message;
  explicit ParamError(std::string m) : message(std::move(m)) {}
  const char* what() const noexcept override { return message.c_str(); }
};

constexpr int kMaxSlots = 64;

struct Params {
  std::array<float, kMaxSlots> values{};
  Params();  // all defaults

  float get(P p, int component = 0) const { return values[slot_of(p) + component]; }
  // Physical value after the declared slider mapping.
  float physical(P p, int component = 0) const;
  vec3 vector(P p) const { return {get(p, 0), get(p, 1), get(p, 2)}; }

  // Validating setters: throw ParamError naming the key and the accepted range
  // for NaN/Inf, out-of-range values, non-integers for Int parameters and
  // wrong component counts.
  void set(P p, const float* components, int count);
  void set(std::string_view key, const float* components, int count);
  void set(P p, float value) { set(p, &value, 1); }

  // Unchecked write, for tests of the kernel at and beyond the limits.
  void set_unchecked(P p, int component, float value) { values[slot_of(p) + component] = value; }
};

// One-line description of the accepted range, e.g. "a number in [0, 1]".
std::string describe_range(const ParamDecl& d);

}  // namespace cg
