// test_golden.cpp — the kernel's output pinned by a committed fingerprint
// (tests/golden/density_fingerprint.json): densities at fixed points for the
// defaults and every preset, each in three variants (as declared; the object
// far from the origin with the texture partly following it; late in time
// with wind), plus kFieldKeyVersion and each case's field key.
//
// Why: a sequence bake and `bake --update` trust the field key, and the key
// only hashes the kernel's *inputs*. When the kernel's *output* changes for
// the same inputs, kFieldKeyVersion (field_key.h) must be bumped or stale
// files are reused. This test notices such a change.
//
// Tolerance: |got - expected| <= 1e-6 x (the preset's largest stored
// density, all variants). Bitwise equality is expected on x86-64 with the
// project's compiler flags (the kernel is float-only, no -march=native); the
// slack only absorbs a different libm's sin/pow/log2 rounding (1 ulp there
// moves a density by far less than 1e-6 of the maximum), while any change to
// a formula or constant moves some point by much more.
//
// Regenerate (after bumping kFieldKeyVersion when the output changed on purpose):
//   CLOUDGEN_WRITE_GOLDEN=1 build/bin/cloudgen_tests --gtest_filter='Golden.*'
// which rewrites the file in the source tree; review and commit the diff.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cloudgen/field_key.h"
#include "cloudgen/param_io.h"
#include "test_util.h"

#ifndef CLOUDGEN_GOLDEN_FILE
#error "CLOUDGEN_GOLDEN_FILE (the fingerprint's path in the source tree) must be defined by the build"
#endif

namespace {

using cg::vec3;

constexpr const char* kRegenerate = "CLOUDGEN_WRITE_GOLDEN=1 build/bin/cloudgen_tests --gtest_filter='Golden.*'";
constexpr double kRelativeTolerance = 1e-6;
constexpr int kPointsPerCase = 12;  // 9 inside the cloud (density > 0) and 3 empty ones where possible

struct Variant {
  const char* name;
  std::function<void(cg::Params&)> apply;
};

const std::vector<Variant>& variants() {
  static const std::vector<Variant> v = {
      {"declared", [](cg::Params&) {}},
      {"far",
       [](cg::Params& p) {
         const float location[3] = {123456.5f, -65432.25f, 2500.75f};
         p.set(cg::OBJECT_LOCATION, location, 3);
         p.set(cg::STATIONARY, 0.3f);
       }},
      {"late",
       [](cg::Params& p) {
         const float wind[3] = {0.6f, -0.8f, 0.1f};
         p.set(cg::WIND_DIRECTION, wind, 3);
         p.set(cg::WIND_STRENGTH, 0.35f);
         p.set(cg::TIME, 5000.25f);
       }},
  };
  return v;
}

// "defaults" and every preset, in the data file's order.
std::vector<std::pair<std::string, cg::Params>> clouds() {
  std::vector<std::pair<std::string, cg::Params>> out = {{"defaults", cg::Params()}};
  for (const cg::Preset& p : cg::presets()) out.emplace_back(p.name, p.params);
  return out;
}

// How a stored number is read back: the writer stores exactly what the reader gets.
float read_back(const std::string& text) { return static_cast<float>(std::strtod(text.c_str(), nullptr)); }
std::string text(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));
  return buf;
}

void write_golden() {
  std::ostringstream o;
  o << "{\n  \"field_key_version\": " << cg::kFieldKeyVersion << ",\n"
    << "  \"about\": \"densities at fixed local points; see tests/native/test_golden.cpp\",\n"
    << "  \"cases\": [";
  bool first_case = true;
  const auto all = clouds();
  for (std::size_t ci = 0; ci < all.size(); ++ci) {
    const auto& [name, declared] = all[ci];
    for (std::size_t vi = 0; vi < variants().size(); ++vi) {
      cg::Params p = declared;
      variants()[vi].apply(p);
      const cg::Model m = cg::prepare(p);
      cgtest::Rng rng(0x601d0000u + 8u * ci + vi);
      std::vector<std::array<float, 4>> rows;
      int inside = 0, empty = 0;
      for (int tries = 0; tries < 20000 && int(rows.size()) < kPointsPerCase; ++tries) {
        vec3 q;
        for (int a = 0; a < 3; ++a) q[a] = read_back(text(m.box[a] * (rng.uniformf(0.05, 0.95) - 0.5f)));
        const float d = cg::density(m, q);
        const bool last_tries = tries >= 19000;  // fill up with whatever comes when a kind is rare
        if (d > 0.0f ? (inside < kPointsPerCase - 3 || last_tries) : (empty < 3 || last_tries)) {
          (d > 0.0f ? inside : empty) += 1;
          rows.push_back({q[0], q[1], q[2], d});
        }
      }
      o << (first_case ? "\n" : ",\n") << "    {\"cloud\": \"" << name << "\", \"variant\": \"" << variants()[vi].name
        << "\", \"field_key\": \"" << cg::field_key(m) << "\",\n     \"points\": [";
      first_case = false;
      for (std::size_t k = 0; k < rows.size(); ++k)
        o << (k ? ",\n                " : "") << "[" << text(rows[k][0]) << ", " << text(rows[k][1]) << ", "
          << text(rows[k][2]) << ", " << text(rows[k][3]) << "]";
      o << "]}";
    }
  }
  o << "\n  ]\n}\n";
  std::ofstream f(CLOUDGEN_GOLDEN_FILE);
  f << o.str();
  ASSERT_TRUE(f.good()) << "cannot write " << CLOUDGEN_GOLDEN_FILE;
  std::printf("wrote %s\n", CLOUDGEN_GOLDEN_FILE);
}

TEST(Golden, KernelMatchesTheDensityFingerprint) {
  const char* write = std::getenv("CLOUDGEN_WRITE_GOLDEN");
  if (write && *write && std::string(write) != "0") return write_golden();

  std::ifstream f(CLOUDGEN_GOLDEN_FILE);
  ASSERT_TRUE(f.good()) << "missing " << CLOUDGEN_GOLDEN_FILE << "; create it with " << kRegenerate;
  const nlohmann::json doc = nlohmann::json::parse(f);
  const std::string advice =
      std::string("the kernel's output changed: bump kFieldKeyVersion and regenerate with ") + kRegenerate;
  ASSERT_EQ(doc.at("field_key_version").get<int>(), cg::kFieldKeyVersion)
      << "the fingerprint was made for another kFieldKeyVersion; regenerate with " << kRegenerate;

  int cases_checked = 0, points_checked = 0;
  for (const auto& [name, declared] : clouds()) {
    // The preset's largest stored density, over all its variants: the tolerance's scale.
    float scale = 0.0f;
    for (const auto& c : doc.at("cases"))
      if (c.at("cloud") == name)
        for (const auto& row : c.at("points")) scale = std::max(scale, row.at(3).get<float>());
    const double tolerance = kRelativeTolerance * double(scale);
    for (const Variant& v : variants()) {
      const nlohmann::json* found = nullptr;
      for (const auto& c : doc.at("cases"))
        if (c.at("cloud") == name && c.at("variant") == v.name) found = &c;
      if (!found) {
        ADD_FAILURE() << "no fingerprint for cloud '" << name << "' variant '" << v.name
                      << "' (a new preset?); regenerate with " << kRegenerate;
        continue;
      }
      cg::Params p = declared;
      v.apply(p);
      const cg::Model m = cg::prepare(p);
      for (const auto& row : found->at("points")) {
        const vec3 q{row.at(0).get<float>(), row.at(1).get<float>(), row.at(2).get<float>()};
        const float expected = row.at(3).get<float>(), got = cg::density(m, q);
        EXPECT_LE(std::fabs(double(got) - double(expected)), tolerance)
            << "cloud '" << name << "' variant '" << v.name << "' point " << cgtest::str(q) << ": expected "
            << text(expected) << ", got " << text(got) << " (tolerance " << tolerance << " = " << kRelativeTolerance
            << " x max density " << scale << ")\n"
            << advice;
        ++points_checked;
      }
      EXPECT_EQ(found->at("field_key").get<std::string>(), cg::field_key(m))
          << "cloud '" << name << "' variant '" << v.name
          << "': the field key changed for the same parameters (keys must stay stable within a kFieldKeyVersion;"
          << " a change of the kernel's inputs, a preset or a variant needs a regeneration with " << kRegenerate << ")";
      ++cases_checked;
    }
  }
  EXPECT_EQ(std::size_t(cases_checked), doc.at("cases").size()) << "the file holds cases no cloud/variant makes";
  EXPECT_GE(points_checked, cases_checked * 6) << "too few points per case in the fingerprint";
}

}  // namespace
