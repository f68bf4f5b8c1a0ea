// test_field_key.cpp — field keys (field_key.h): a change the kernel can see
// changes the key, a change it cannot see keeps it.
//
// The parameter tests loop over kParams and the model test over the rows of
// model_fields.h, so a new parameter or Model field is covered without
// editing this file. Densities are compared exactly (bitwise): "moved" means
// some sample point's density changed at all; no tolerance is involved.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "cloudgen/field_key.h"
#include "cloudgen/param_io.h"
#include "test_util.h"

namespace {

using cg::vec3;
using cgtest::str;

cg::Params preset(const char* name) {
  const cg::Preset* p = cg::find_preset(name);
  EXPECT_NE(p, nullptr) << "preset '" << name << "' missing";
  return p ? p->params : cg::Params();
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Sample points: fixed pseudo-random local points inside a box of `size`
// (generated coordinates in [0.02, 0.98]).
std::vector<vec3> sample_points(vec3 size, int n, std::uint64_t seed) {
  cgtest::Rng rng(seed);
  std::vector<vec3> out;
  for (int k = 0; k < n; ++k) {
    vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = size[a] * (rng.uniformf(0.02, 0.98) - 0.5f);
    out.push_back(p);
  }
  return out;
}

// The first sample point where the two fields differ, or -1.
int first_difference(const cg::Model& a, const cg::Model& b, const std::vector<vec3>& points) {
  for (std::size_t k = 0; k < points.size(); ++k)
    if (!same_bits(cg::density(a, points[k]), cg::density(b, points[k]))) return int(k);
  return -1;
}

// A base with every parameter live: wind, evolution, a moved object that the
// texture half follows, and shape mode `mode`.
cg::Params live_base(int mode) {
  cg::Params p;
  p.set(cg::SHAPE_MODE, float(mode));
  p.set(cg::WIND_STRENGTH, 0.3f);
  p.set(cg::TURRET_INFLUENCE, 0.3f);  // else Turret Size has no effect
  p.set(cg::WARP, 0.3f);              // else Warp Size has no effect
  p.set(cg::ANVIL, 0.3f);             // else Anvil Height has no effect
  const float wind[3] = {1.0f, 0.5f, -0.25f};
  p.set(cg::WIND_DIRECTION, wind, 3);
  p.set(cg::TIME, 7.25f);
  p.set(cg::STATIONARY, 0.5f);
  const float location[3] = {3.0f, -2.0f, 1.0f};
  p.set(cg::OBJECT_LOCATION, location, 3);
  return p;
}

// Values to try for one component: the ends and the middle of the slider range.
std::vector<float> trial_values(const cg::ParamDecl& d) {
  std::vector<float> v = {d.soft_min, d.soft_max, 0.5f * (d.soft_min + d.soft_max)};
  if (d.kind == cg::Kind::Int) v[2] = std::floor(v[2]);
  return v;
}

TEST(FieldKey, TimeDropsOutOfAStillCloudOnly) {
  cg::Params still = preset("cumulus");
  still.set(cg::EVOLUTION, 0.0f);
  still.set(cg::WIND_STRENGTH, 0.0f);
  cg::Params later = still;
  later.set(cg::TIME, 12.5f);
  EXPECT_EQ(cg::field_key(still), cg::field_key(later)) << "no wind, no evolution: time cannot change the field";
  cg::Params evolving = still, evolving_later = still;
  evolving.set(cg::EVOLUTION, 0.1f);
  evolving_later.set(cg::EVOLUTION, 0.1f);
  evolving_later.set(cg::TIME, 12.5f);
  EXPECT_NE(cg::field_key(evolving), cg::field_key(evolving_later));
  EXPECT_EQ(cg::field_key(still).size(), 16u);
}

TEST(FieldKey, EveryParameterThatMovesTheDensityMovesTheKey) {
  // For every declared parameter and component, each trial value (slider
  // ends and middle) is set on two live bases (shape mode 0 and 1). Where the
  // density moves at some sample point, the key must move. Every parameter
  // must move the density at least once, else the bases do not exercise it.
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const cg::ParamDecl& d = cg::kParams[i];
    int moved = 0;
    for (int mode = 0; mode < 2; ++mode) {
      const cg::Params base = live_base(mode);
      const cg::Model mb = cg::prepare(base);
      const std::string kb = cg::field_key(mb);
      const std::vector<vec3> points = sample_points(mb.box, 300, 11u + unsigned(mode));
      for (int c = 0; c < cg::component_count(d.kind); ++c) {
        for (float v : trial_values(d)) {
          if (v == base.get(cg::P(i), c)) continue;
          cg::Params changed = base;
          changed.set_unchecked(cg::P(i), c, v);
          const cg::Model mc = cg::prepare(changed);
          const int k = first_difference(mb, mc, points);
          if (k < 0) continue;
          ++moved;
          EXPECT_NE(cg::field_key(mc), kb)
              << d.key << "[" << c << "]: " << base.get(cg::P(i), c) << " -> " << v << " (shape mode " << mode
              << ") moves the density at " << str(points[k]) << " from " << cg::density(mb, points[k]) << " to "
              << cg::density(mc, points[k]) << " but keeps the key " << kb << "; base " << cgtest::describe(base);
        }
      }
    }
    EXPECT_GT(moved, 0) << "no trial value of '" << d.key
                        << "' moved the density at the sample points: extend live_base() or trial_values()";
  }
}

TEST(FieldKey, ChangesTheKernelCannotSeeKeepTheKey) {
  // Each case: a base and a change the kernel provably ignores. The key must
  // stay and (as a check of the case itself) so must every sample density.
  struct Case {
    const char* what;
    cg::Params base;
    std::function<void(cg::Params&)> change;
  };
  std::vector<Case> cases;
  {
    cg::Params still = live_base(0);
    still.set(cg::WIND_STRENGTH, 0.0f);
    still.set(cg::EVOLUTION, 0.0f);
    cases.push_back({"time, with no wind and no evolution", still, [](cg::Params& p) { p.set(cg::TIME, 99.0f); }});
    const float dir[3] = {0.0f, -1.0f, 0.5f};
    cases.push_back(
        {"wind direction, with no wind", still, [dir](cg::Params& p) { p.set(cg::WIND_DIRECTION, dir, 3); }});
  }
  {
    const float half[3] = {0.5f, 0.25f, -0.125f};  // live_base's direction halved: the same unit vector
    cases.push_back(
        {"wind direction's length", live_base(1), [half](cg::Params& p) { p.set(cg::WIND_DIRECTION, half, 3); }});
  }
  {
    cg::Params follows = live_base(1);
    follows.set(cg::STATIONARY, 1.0f);
    const float far[3] = {-40.0f, 17.0f, 3.5f};
    cases.push_back(
        {"object location, with Stationary 1", follows, [far](cg::Params& p) { p.set(cg::OBJECT_LOCATION, far, 3); }});
  }
  cases.push_back(
      {"shape curve, in shape mode 0", live_base(0), [](cg::Params& p) { p.set_unchecked(cg::SHAPE_CURVE, 6, 0.1f); }});
  cases.push_back(
      {"shape exponent, in shape mode 1", live_base(1), [](cg::Params& p) { p.set(cg::SHAPE_EXPONENT, 3.0f); }});
  // Density 0: every parameter's every trial value keeps the one empty key.
  for (int mode = 0; mode < 2; ++mode) {
    cg::Params empty = live_base(mode);
    empty.set(cg::DENSITY, 0.0f);
    for (int i = 0; i < cg::PARAM_COUNT; ++i) {
      if (i == cg::DENSITY) continue;
      const cg::ParamDecl& d = cg::kParams[i];
      for (int c = 0; c < cg::component_count(d.kind); ++c)
        for (float v : trial_values(d))
          cases.push_back({d.key, empty, [i, c, v](cg::Params& p) { p.set_unchecked(cg::P(i), c, v); }});
    }
  }
  for (const Case& k : cases) {
    cg::Params changed = k.base;
    k.change(changed);
    const cg::Model ma = cg::prepare(k.base), mb = cg::prepare(changed);
    const std::vector<vec3> points = sample_points(ma.box, 100, 5);
    const int diff = first_difference(ma, mb, points);
    EXPECT_LT(diff, 0) << k.what << ": the case is wrong, the density moves at "
                       << (diff < 0 ? std::string("-") : str(points[diff]));
    EXPECT_EQ(cg::field_key(ma), cg::field_key(mb))
        << k.what << ": the key moved; base " << cgtest::describe(k.base) << ", changed " << cgtest::describe(changed);
  }
}

// Applies `check` after perturbing each scalar of a Model field in turn (the
// field is restored after each check).
template <class F>
void perturb_each(float& v, F check) {
  const float old = v;
  v = std::nextafter(v, std::numeric_limits<float>::infinity());
  check();
  v = old;
}
template <class F>
void perturb_each(int& v, F check) {
  v += 1;
  check();
  v -= 1;
}
template <class F>
void perturb_each(vec3& v, F check) {
  for (int c = 0; c < 3; ++c) perturb_each(v[c], check);
}
template <class F, std::size_t N>
void perturb_each(float (&a)[N], F check) {
  for (float& v : a) perturb_each(v, check);
}

TEST(FieldKey, EveryModelFieldIsHashed) {
  // The smallest change of any scalar of any Model field (one ulp, or +1 for
  // an int) changes the key, unless the field's key_rule says the shape mode
  // hides it — then the key stays. Rows from model_fields.h.
  for (int mode = 0; mode < 2; ++mode) {
    cg::Model m = cg::prepare(live_base(mode));
    const std::string base = cg::field_key(m);
    const auto reaches = [&](const std::string& rule) {
      return rule == "Always" || (rule == "ExponentShape" && mode != 1) || (rule == "CurveShape" && mode == 1);
    };
#define CG_MODEL_FIELD(type, name, key_rule)                                                          \
  perturb_each(m.name, [&] {                                                                          \
    if (reaches(#key_rule))                                                                           \
      EXPECT_NE(cg::field_key(m), base) << "Model::" #name " (shape mode " << mode << ") not hashed"; \
    else                                                                                              \
      EXPECT_EQ(cg::field_key(m), base) << "Model::" #name " (shape mode " << mode << ", " #key_rule  \
                                        << ") hashed where it cannot reach the field";                \
  });
#define CG_MODEL_ARRAY(type, name, count, key_rule) CG_MODEL_FIELD(type, name, key_rule)
#include "cloudgen/model_fields.h"
#undef CG_MODEL_ARRAY
#undef CG_MODEL_FIELD
  }
}

}  // namespace
