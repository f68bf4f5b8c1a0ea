// test_params.cpp — the parameter declarations (params.h), validation at the
// boundary (Params::set), presets and JSON parameter files (param_io.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "cloudgen/param_io.h"
#include "cloudgen/params.h"
#include "test_util.h"

namespace {

using cgtest::Rng;

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

bool same_values(const cg::Params& a, const cg::Params& b) {
  return std::memcmp(a.values.data(), b.values.data(), sizeof(float) * std::size_t(cg::slot_count())) == 0;
}

TEST(Params, DeclarationsAreConsistent) {
  std::set<std::string> keys;
  int slot = 0;
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const cg::ParamDecl& d = cg::kParams[i];
    const std::string key = d.key;
    SCOPED_TRACE("parameter '" + key + "'");
    EXPECT_FALSE(key.empty());
    EXPECT_TRUE(keys.insert(key).second) << "duplicate key";
    EXPECT_EQ(cg::find_param(key), cg::P(i));
    EXPECT_GT(std::strlen(d.label), 0u);
    EXPECT_GT(std::strlen(d.help), 0u);
    EXPECT_TRUE(std::isfinite(d.min) && std::isfinite(d.max));
    EXPECT_LT(d.min, d.max);
    EXPECT_LE(d.min, d.soft_min);
    EXPECT_LT(d.soft_min, d.soft_max);
    EXPECT_LE(d.soft_max, d.max);
    EXPECT_NE(d.map_lo, d.map_hi) << "a mapping must not collapse the range";
    // Slot layout: consecutive, in declaration order.
    EXPECT_EQ(cg::slot_of(cg::P(i)), slot);
    slot += cg::component_count(d.kind);
    // Defaults inside the hard range; Int defaults integral.
    const cg::Params defaults;
    for (int c = 0; c < cg::component_count(d.kind); ++c) {
      const float v = defaults.get(cg::P(i), c);
      EXPECT_GE(v, d.min) << "default component " << c;
      EXPECT_LE(v, d.max) << "default component " << c;
      if (d.kind == cg::Kind::Int) {
        EXPECT_EQ(v, std::floor(v));
      }
      const float declared = d.kind == cg::Kind::Curve ? cg::kDefaultCurve[c] : d.default_value[c];
      EXPECT_EQ(v, declared) << "component " << c;
    }
  }
  EXPECT_EQ(cg::slot_count(), slot);
  EXPECT_LE(cg::slot_count(), cg::kMaxSlots);
  EXPECT_FALSE(cg::find_param("no_such_parameter").has_value());
  EXPECT_EQ(cg::component_count(cg::Kind::Curve), CG_CURVE_POINTS);
  EXPECT_EQ(cg::component_count(cg::Kind::Vector), 3);
  // The Density mapping is the shared constant (used by the OSL side too).
  EXPECT_EQ(cg::Params().physical(cg::DENSITY), 0.5f * float(CG_DENSITY_SCALE));
}

TEST(Params, EveryEnumValueNamesItsRow) {
  // param_list.h makes the enum and the table from the same rows; this pins
  // the convention that a row's key is its enumerator in lower case, and
  // that kParams[ENUM] is that row (exact string comparison).
  struct Row {
    cg::P p;
    const char* enumerator;
    const char* key;
  };
  const Row rows[] = {
#define CG_PARAM(ENUM, key, ...) {cg::ENUM, #ENUM, key},
#include "cloudgen/param_list.h"
#undef CG_PARAM
  };
  ASSERT_EQ(std::size(rows), std::size_t(cg::PARAM_COUNT));
  for (std::size_t i = 0; i < std::size(rows); ++i) {
    const Row& r = rows[i];
    std::string lower = r.enumerator;
    for (char& ch : lower) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    EXPECT_EQ(int(r.p), int(i)) << r.enumerator << ": enum value out of row order";
    EXPECT_STREQ(cg::kParams[r.p].key, r.key) << "kParams[" << r.enumerator << "]";
    EXPECT_EQ(lower, r.key) << "the key of row " << r.enumerator << " is not its enumerator in lower case";
  }
}

TEST(Params, PresetsAreWithinRange) {
  ASSERT_FALSE(cg::presets().empty());
  ASSERT_NE(cg::find_preset("cumulus"), nullptr);
  EXPECT_EQ(cg::find_preset("no such cloud"), nullptr);
  for (const cg::Preset& p : cg::presets()) {
    SCOPED_TRACE("preset '" + p.name + "'");
    EXPECT_FALSE(p.description.empty());
    for (int i = 0; i < cg::PARAM_COUNT; ++i) {
      const cg::ParamDecl& d = cg::kParams[i];
      for (int c = 0; c < cg::component_count(d.kind); ++c) {
        const float v = p.params.get(cg::P(i), c);
        EXPECT_TRUE(std::isfinite(v) && v >= d.min && v <= d.max) << d.key << "[" << c << "] = " << v;
        if (d.kind == cg::Kind::Int) {
          EXPECT_EQ(v, std::floor(v)) << d.key;
        }
      }
    }
  }
}

// Expects `f` to throw a ParamError whose message contains every string in `parts`.
template <class F>
void expect_param_error(F f, const std::vector<std::string>& parts, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << what << ": no ParamError";
  } catch (const cg::ParamError& e) {
    for (const std::string& part : parts)
      EXPECT_TRUE(contains(e.what(), part)) << what << ": message \"" << e.what() << "\" lacks \"" << part << "\"";
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": wrong exception: " << e.what();
  }
}

TEST(Params, PresetMaterials) {
  // Every preset has material settings, all known keys, values in range.
  for (const cg::Preset& p : cg::presets()) {
    SCOPED_TRACE("preset '" + p.name + "'");
    EXPECT_FALSE(p.material.empty());
    EXPECT_EQ(p.material_json.front(), '{');
    for (const cg::MaterialValue& m : p.material)
      EXPECT_NE(std::find(cg::material_keys().begin(), cg::material_keys().end(), m.key), cg::material_keys().end());
  }
  const auto parse = [](const std::string& material) {
    return
        [material] { cg::parse_presets(R"({"x": {"description": "d", "params": {}, "material": )" + material + "}}"); };
  };
  EXPECT_EQ(cg::parse_presets(R"({"x": {"params": {}}})").at(0).material_json, "{}");
  const auto ok =
      cg::parse_presets(R"({"x": {"params": {}, "material": {"anisotropy": 0.5, "color": [1, 0.9, 0.8]}}})");
  ASSERT_EQ(ok.at(0).material.size(), 2u);
  EXPECT_EQ(ok.at(0).material[1].values, (std::vector<double>{1, 0.9, 0.8}));
  expect_param_error(parse(R"({"shininess": 1})"), {"preset 'x'", "unknown material key 'shininess'", "anisotropy"},
                     "unknown key");
  expect_param_error(parse(R"({"anisotropy": "high"})"), {"preset 'x'", "'anisotropy'", "a number", "\"high\""},
                     "text");
  expect_param_error(parse(R"({"anisotropy": 1.5})"), {"'anisotropy'", "[-1, 1]"}, "out of range");
  expect_param_error(parse(R"({"color": [1, 1]})"), {"'color'", "3 numbers"}, "short colour");
  expect_param_error(parse(R"({"halo": -0.5})"), {"'halo'", "[0, 10]"}, "negative halo");
  EXPECT_EQ(cg::parse_presets(R"({"x": {"params": {}, "material": {"halo": 1}}})").at(0).material.at(0).key, "halo");
  expect_param_error(parse(R"({"backscatter": 0})"), {"'backscatter'", "[0.001, 0.49]"}, "backscatter 0: a delta");
  expect_param_error(parse(R"({"backscatter": 0.5})"), {"'backscatter'", "[0.001, 0.49]"}, "backscatter 0.5");
  expect_param_error(parse(R"({"side_scatter": 0.6})"), {"'side_scatter'", "[0, 0.5]"}, "side scatter 0.6");
  expect_param_error(parse(R"({"color": [1, "1", 1]})"), {"'color'", "3 numbers"}, "colour with text");
  expect_param_error(parse(R"([1])"), {"'material' must be an object"}, "not an object");
  expect_param_error([] { cg::parse_presets(R"({"x": {"params": {}, "shader": {}}})"); }, {"unknown key 'shader'"},
                     "unknown preset key");
}

TEST(Params, SetRefusesBadValuesNamingKeyAndRange) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const cg::ParamDecl& d = cg::kParams[i];
    const cg::P p = cg::P(i);
    const int n = cg::component_count(d.kind);
    const std::vector<std::string> parts = {d.key, cg::describe_range(d)};
    const cg::Params defaults;
    std::vector<float> good(static_cast<std::size_t>(n), 0.0f);
    for (int c = 0; c < n; ++c) good[std::size_t(c)] = defaults.get(p, c);
    const float range = d.max - d.min;
    for (float bad : {nan, inf, -inf, d.max + std::max(1.0f, range), d.min - std::max(1.0f, range)}) {
      for (int c : {0, n - 1}) {
        std::vector<float> v = good;
        v[std::size_t(c)] = bad;
        cg::Params q;
        expect_param_error([&] { q.set(p, v.data(), n); }, parts,
                           std::string(d.key) + "[" + std::to_string(c) + "] = " + std::to_string(bad));
        EXPECT_TRUE(same_values(q, defaults)) << d.key << ": a refused set must not change anything";
        expect_param_error([&] { q.set(std::string_view(d.key), v.data(), n); }, parts, std::string("by key ") + d.key);
      }
    }
    if (d.kind == cg::Kind::Int) {
      const float half = d.min + 0.5f;
      cg::Params q;
      expect_param_error([&] { q.set(p, half); }, parts, std::string(d.key) + " non-integer");
    }
    // Wrong component counts.
    std::vector<float> longer(std::size_t(n + 1), d.min);
    cg::Params q;
    expect_param_error([&] { q.set(p, longer.data(), n + 1); }, {d.key}, std::string(d.key) + " too many values");
    if (n > 1) expect_param_error([&] { q.set(p, longer.data(), 1); }, {d.key}, std::string(d.key) + " too few values");
    // The limits themselves are accepted.
    std::vector<float> lo(std::size_t(n), d.min), hi(std::size_t(n), d.max);
    EXPECT_NO_THROW(q.set(p, lo.data(), n)) << d.key;
    EXPECT_NO_THROW(q.set(p, hi.data(), n)) << d.key;
    EXPECT_EQ(q.get(p, n - 1), d.max);
  }
  cg::Params q;
  const float one = 1;
  expect_param_error([&] { q.set(std::string_view("cloud_size"), &one, 1); }, {"cloud_size"}, "unknown key");
}

TEST(ParamsJson, ErrorsNameTheProblem) {
  struct Bad {
    const char* text;
    std::vector<std::string> parts;
  };
  const Bad cases[] = {
      {"{\"density\": 0.5,, }", {"not valid JSON"}},
      {"{\"density\": 0.5, \"box_size\": [1, 2", {"not valid JSON"}},
      {"{\"density\": 0.", {"not valid JSON"}},
      {"", {"not valid JSON"}},
      {"[1, 2, 3]", {"object"}},
      {"{\"densityy\": 0.5}", {"densityy", "unknown"}},
      {"{\"preset\": \"nimbostratus-x\"}", {"nimbostratus-x", "preset"}},
      {"{\"preset\": 3}", {"preset"}},
      {"{\"density\": \"thick\"}", {"density", "[0, 10]"}},
      {"{\"density\": null}", {"density"}},
      {"{\"density\": [0.5]}", {"density"}},
      {"{\"box_size\": 3}", {"box_size"}},
      {"{\"box_size\": [1, 2]}", {"box_size"}},
      {"{\"box_size\": [1, \"2\", 3]}", {"box_size"}},
      {"{\"shape_curve\": [0, 1]}", {"shape_curve"}},
      {"{\"seed\": 1.5}", {"seed", "integer"}},
      {"{\"density\": 11}", {"density", "[0, 10]"}},
      {"{\"cloud_scale\": -1}", {"cloud_scale"}},
      {"{\"time\": 1e300}", {"time"}},
      {"{\"wind_direction\": [0, 0, 2]}", {"wind_direction"}},
  };
  for (const Bad& b : cases) {
    std::vector<std::string> parts = b.parts;
    parts.push_back("myfile.json");  // the origin is named too
    expect_param_error([&] { (void)cg::params_from_json(b.text, "myfile.json"); }, parts,
                       std::string("JSON ") + b.text);
  }
}

TEST(ParamsJson, PresetsAndOverrides) {
  const cg::Params cumulus = cg::find_preset("cumulus")->params;
  EXPECT_TRUE(same_values(cg::params_from_json("{\"preset\": \"cumulus\"}"), cumulus));
  const cg::Params p = cg::params_from_json("{\"preset\": \"cumulus\", \"density\": 0.25, \"seed\": 7}");
  EXPECT_EQ(p.get(cg::DENSITY), 0.25f);
  EXPECT_EQ(p.get(cg::SEED), 7.0f);
  EXPECT_EQ(p.get(cg::BOX_SIZE, 2), cumulus.get(cg::BOX_SIZE, 2));
  EXPECT_TRUE(same_values(cg::params_from_json("{}"), cg::Params()));
}

TEST(ParamsJson, RoundTripIsExact) {
  // Tolerance 0 (bitwise): params_from_json(params_to_json(p)) == p for the defaults,
  // every preset, the limits and random values (integers for Int parameters).
  std::vector<cg::Params> cases = {cg::Params()};
  for (const cg::Preset& p : cg::presets()) cases.push_back(p.params);
  cg::Params lo, hi;
  for (int i = 0; i < cg::PARAM_COUNT; ++i)
    for (int c = 0; c < cg::component_count(cg::kParams[i].kind); ++c) {
      lo.set_unchecked(cg::P(i), c, cg::kParams[i].min);
      hi.set_unchecked(cg::P(i), c, cg::kParams[i].max);
    }
  cases.push_back(lo);
  cases.push_back(hi);
  Rng rng(41);
  for (int r = 0; r < 200; ++r) {
    cg::Params p;
    for (int i = 0; i < cg::PARAM_COUNT; ++i) {
      const cg::ParamDecl& d = cg::kParams[i];
      for (int c = 0; c < cg::component_count(d.kind); ++c) {
        float v = rng.uniformf(double(d.min), double(d.max));
        if (d.kind == cg::Kind::Int) v = std::floor(v);
        v = std::min(std::max(v, d.min), d.max);
        p.set_unchecked(cg::P(i), c, v);
      }
    }
    cases.push_back(p);
  }
  for (const cg::Params& p : cases) {
    for (int indent : {-1, 2}) {
      const std::string text = cg::params_to_json(p, indent);
      const cg::Params back = cg::params_from_json(text, "round trip");
      EXPECT_TRUE(same_values(back, p)) << "through " << text;
    }
  }
}

TEST(ParamsJson, DeclarationsJsonListsEveryParameter) {
  const std::string text = cg::declarations_json();
  for (int i = 0; i < cg::PARAM_COUNT; ++i)
    EXPECT_TRUE(contains(text, std::string("\"") + cg::kParams[i].key + "\"")) << cg::kParams[i].key;
  EXPECT_FALSE(std::string(cg::version()).empty());
}

}  // namespace
