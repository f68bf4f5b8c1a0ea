// test_tiers.cpp — the quality tiers data file and its parser (tiers.h).
#include <gtest/gtest.h>

#include <string>

#include "cloudgen/params.h"  // ParamError
#include "cloudgen/tiers.h"

namespace {

TEST(Tiers, DataFileHasDraftPreviewFinalInOrderOfCost) {
  const auto& t = cg::tiers();
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].name, "draft");
  EXPECT_EQ(t[1].name, "preview");
  EXPECT_EQ(t[2].name, "final");
  for (std::size_t i = 1; i < t.size(); ++i) {
    EXPECT_GE(t[i].render_samples, t[i - 1].render_samples) << t[i].name;
    EXPECT_LE(t[i].render_step_rate, t[i - 1].render_step_rate) << t[i].name << " (smaller steps cost more)";
    EXPECT_GE(t[i].bake_resolution, t[i - 1].bake_resolution) << t[i].name;
  }
  EXPECT_EQ(cg::find_tier("nope"), nullptr);
}

TEST(Tiers, BadTiersNameTheTierAndKey) {
  const std::string ok_render = "\"render\": {\"samples\": 4, \"step_rate\": 1}";
  const std::string ok_bake = "\"bake\": {\"resolution\": 8, \"lod\": true, \"tolerance\": 0, \"half\": false}";
  const std::string ok_preview = "\"preview\": {\"size\": 8}";
  const auto tier = [&](const std::string& render, const std::string& bake) {
    return "{\"t\": {\"label\": \"T\", \"description\": \"d\", " + render + ", " + bake + ", " + ok_preview + "}}";
  };
  EXPECT_EQ(cg::parse_tiers(tier(ok_render, ok_bake)).size(), 1u);
  try {
    cg::parse_tiers(tier("\"render\": {\"samples\": 4.5, \"step_rate\": 1}", ok_bake));
    ADD_FAILURE() << "fractional samples accepted";
  } catch (const cg::ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("tier 't'.render.samples"), std::string::npos) << e.what();
  }
  try {
    cg::parse_tiers(tier(ok_render, "\"bake\": {\"resolution\": 8, \"lod\": 1, \"tolerance\": 0, \"half\": false}"));
    ADD_FAILURE() << "numeric lod accepted";
  } catch (const cg::ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("lod"), std::string::npos) << e.what();
  }
}

}  // namespace
