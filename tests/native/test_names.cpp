// test_names.cpp — case-insensitive names and "did you mean" (cloudgen/names.h). Exact strings.
#include <gtest/gtest.h>

#include "cloudgen/names.h"
#include "cloudgen/param_io.h"
#include "cloudgen/params.h"
#include "cloudgen/tiers.h"

namespace {

TEST(Names, PresetsAndTiersIgnoreCase) {
  ASSERT_NE(cg::find_preset("Cumulus"), nullptr);
  EXPECT_EQ(cg::find_preset("CUMULUS_CONGESTUS")->name, "cumulus_congestus");
  EXPECT_EQ(cg::find_preset("cumulo"), nullptr);
  ASSERT_NE(cg::find_tier("Draft"), nullptr);
  EXPECT_EQ(cg::find_tier("Draft")->name, "draft");
}

TEST(Names, DidYouMean) {
  const std::vector<std::string> known = {"density", "distortion", "seed"};
  EXPECT_EQ(cg::did_you_mean("densty", known), "; did you mean 'density'?");
  EXPECT_EQ(cg::did_you_mean("DENSITY", known), "; did you mean 'density'?");
  EXPECT_EQ(cg::did_you_mean("sed", known), "; did you mean 'seed'?");
  EXPECT_EQ(cg::did_you_mean("colour", known), "") << "nothing close: no guess";
  EXPECT_EQ(cg::did_you_mean(std::string(5000, 'x'), known), "") << "a document is not a name";
  EXPECT_EQ(cg::closest_name("--resolutoin", {"--resolution", "--output"}), "--resolution");
}

TEST(Names, UnknownParameterSuggestsTheKey) {
  cg::Params p;
  const float one = 1.0f;
  try {
    p.set("noise_detial", &one, 1);
    FAIL() << "an unknown key must be refused";
  } catch (const cg::ParamError& e) {
    EXPECT_NE(e.message.find("did you mean 'noise_detail'?"), std::string::npos) << e.message;
  }
}

TEST(Names, JsonTagRemoved) {
  EXPECT_EQ(cg::json_error_text("[json.exception.parse_error.101] parse error at line 1"), "parse error at line 1");
  EXPECT_EQ(cg::json_error_text("plain"), "plain");
  EXPECT_EQ(cg::json_error_text("[json.exception.x]"), "");
}

}  // namespace
