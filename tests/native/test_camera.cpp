// test_camera.cpp — the camera-aware bake (camera.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cloudgen/camera.h"
#include "cloudgen/grid.h"
#include "cloudgen/param_io.h"
#include "test_util.h"

namespace {

using cg::vec3;

using cgtest::preset;

// The cumulus as it was until 2026-11-29, in a 4 x 4 x 2.4 box at Cloud Scale 0.9 (the Python
// CLI tests' CUMULUS_4X4): the geometry below is worked out for that box, whatever the
// preset's box is now.
cg::Params cumulus_in_4x4_box() {
  cg::Params p = preset("cumulus");
  const float box[3] = {4.0f, 4.0f, 2.4f};
  p.set(cg::BOX_SIZE, box, 3);
  p.set(cg::CLOUD_SCALE, 0.9f);
  return p;
}

// A camera at `eye` looking along +y (Blender: rotation X = 90°), given as JSON.
std::string camera_json(vec3 eye, double tan_x, double tan_y, int w, int h, const std::string& extra = "") {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "{\"camera_to_cloud\": [[1,0,0,%g],[0,0,-1,%g],[0,1,0,%g],[0,0,0,1]],"
                " \"tan_half_fov\": [%g, %g], \"resolution\": [%d, %d]%s}",
                double(eye[0]), double(eye[1]), double(eye[2]), tan_x, tan_y, w, h, extra.c_str());
  return buf;
}

TEST(Camera, NearestDepthAndFootprintOfABoxInFullView) {
  // Cumulus box 4 x 4 x 2.4 centred at the origin, camera 8 units in front of
  // its centre: the nearest visible point is the near face, depth 8 - 2 = 6.
  const cg::Model m = cg::prepare(cumulus_in_4x4_box());
  const cg::CameraView c = cg::parse_camera(camera_json({0, -8, 0}, 0.5, 0.375, 400, 300));
  const cg::CameraFit fit = cg::fit_camera(m, c);
  ASSERT_TRUE(fit.visible);
  EXPECT_NEAR(fit.nearest_depth, 6.0f, 1e-4f) << "tolerance 1e-4 scene units";
  // footprint = 2 · depth · tan / pixels = 2 · 6 · 0.5 / 400 = 0.015
  EXPECT_NEAR(fit.footprint, 0.015f, 1e-6f) << "tolerance 1e-6";
  EXPECT_NEAR(fit.voxel, fit.footprint, 1e-9f) << "pixels_per_voxel 1";
  EXPECT_NEAR(fit.margin, cg::default_margin(m), 1e-9f);
}

TEST(Camera, NarrowViewOfTheBoxEdgeUsesTheVisiblePartOnly) {
  // Looking past the box: the view only grazes the far half of the box's
  // right side, so the nearest *visible* point is farther than the box's
  // nearest point (the near face at depth 6 is outside the view).
  const cg::Model m = cg::prepare(cumulus_in_4x4_box());
  // Camera at x = 3 (outside the box's x range [-2, 2]) looking along +y with
  // a narrow view (tan 0.125): the view reaches x = 2 only at depth (3-2)/0.125 = 8.
  const cg::CameraView c = cg::parse_camera(camera_json({3, -8, 0}, 0.125, 0.125, 100, 100));
  const cg::CameraFit fit = cg::fit_camera(m, c);
  ASSERT_TRUE(fit.visible);
  EXPECT_NEAR(fit.nearest_depth, 8.0f, 1e-3f) << "tolerance 1e-3 scene units";
}

TEST(Camera, CloudOutsideTheViewIsNotVisibleAndBakesNothing) {
  const cg::Model m = cg::prepare(cumulus_in_4x4_box());
  // Looking away (+y camera at y = -8 turned around: rotation X = -90°).
  const std::string json =
      "{\"camera_to_cloud\": [[1,0,0,0],[0,0,1,-8],[0,-1,0,0],[0,0,0,1]], \"tan_half_fov\": [0.5, 0.4],"
      " \"resolution\": [64, 48], \"margin\": 0}";
  const cg::CameraFit fit = cg::fit_camera(m, cg::parse_camera(json));
  EXPECT_FALSE(fit.visible);
  EXPECT_EQ(fit.voxel, 4.0f) << "not visible: one voxel over the box (its longest side)";
  cg::BakeOptions o;
  o.resolution = 32;
  o.use_region = true;
  o.region = fit.region;
  const cg::BakeResult r = cg::bake(m, o);
  EXPECT_EQ(r.stats.tiles_evaluated, 0) << "every tile is behind the camera";
  EXPECT_EQ(r.stats.voxels_evaluated, 0);
  EXPECT_TRUE(r.tiles.empty());
}

TEST(Camera, RegionBakeEqualsTheFullBakeInsideTheView) {
  // A narrow view of the cumulus: tiles the region keeps hold exactly the
  // values of the full bake (same grid, same LOD); culled tiles are outside.
  // Cloud Scale 1: the cloud reaches the box's sides, so the culled tiles hold cloud
  // (at the preset's smaller Cloud Scale the view's margin culls only tiles the shape bound skips anyway).
  cg::Params p = preset("cumulus");
  p.set(cg::CLOUD_SCALE, 1.0f);
  const cg::Model m = cg::prepare(p);
  const cg::CameraView c = cg::parse_camera(camera_json({0, -8, 0}, 0.12, 0.12, 64, 64, ", \"margin\": 0.25"));
  const cg::CameraFit fit = cg::fit_camera(m, c);
  cg::BakeOptions full;
  full.resolution = 40;
  cg::BakeOptions part = full;
  part.use_region = true;
  part.region = fit.region;
  const cg::BakeResult a = cg::bake(m, full), b = cg::bake(m, part);
  EXPECT_GT(b.stats.tiles_culled, 0) << "a narrow view must cull tiles";
  EXPECT_LT(b.stats.voxels_evaluated, a.stats.voxels_evaluated);
  std::size_t j = 0;
  int compared = 0;
  for (const cg::Tile& t : b.tiles) {
    while (j < a.tiles.size() && a.tiles[j].index < t.index) ++j;
    ASSERT_LT(j, a.tiles.size());
    ASSERT_EQ(a.tiles[j].index, t.index);
    for (int v = 0; v < cg::kTileVoxels; ++v) ASSERT_EQ(a.tiles[j].values[v], t.values[v]) << "voxel " << v;
    ++compared;
  }
  EXPECT_GT(compared, 0);
  // Every voxel centre inside the view (un-widened frustum) lies in a kept tile.
  const cg::Frustum view = cg::view_frustum(c, 0.0f);
  for (const cg::Tile& t : a.tiles) {
    const vec3 lo = a.grid.centre(t.index[0], t.index[1], t.index[2]);
    const vec3 hi = a.grid.centre(t.index[0] + 7, t.index[1] + 7, t.index[2] + 7);
    if (cg::box_outside(view, lo, hi)) continue;
    bool kept = false;
    for (const cg::Tile& u : b.tiles) kept = kept || u.index == t.index;
    EXPECT_TRUE(kept) << "tile at " << t.index[0] << "," << t.index[1] << "," << t.index[2]
                      << " is in view but was culled";
  }
}

TEST(Camera, LightSweepKeepsCloudBetweenTheViewAndTheSun) {
  // Camera looks at the lower half only (narrow view aimed below the box
  // centre); a sun straight above: the upper part shades the view and must be
  // kept with the light, may be culled without it.
  const cg::Model m = cg::prepare(preset("cumulus"));
  const std::string base = camera_json({0, -8, -1.0f}, 0.08, 0.08, 64, 64, ", \"margin\": 0");
  const cg::CameraView no_light = cg::parse_camera(base);
  const cg::CameraView sun = cg::parse_camera(
      camera_json({0, -8, -1.0f}, 0.08, 0.08, 64, 64, ", \"margin\": 0, \"light_directions\": [[0, 0, 1]]"));
  const vec3 lo{-0.2f, -0.2f, 1.0f}, hi{0.2f, 0.2f, 1.4f};  // above the view, under the sun
  EXPECT_TRUE(cg::box_outside(cg::fit_camera(m, no_light).region, lo, hi));
  EXPECT_FALSE(cg::box_outside(cg::fit_camera(m, sun).region, lo, hi));
  // A box beside the view, not between it and the sun, stays culled.
  EXPECT_TRUE(cg::box_outside(cg::fit_camera(m, sun).region, {1.5f, -0.2f, -1.2f}, {1.9f, 0.2f, -0.8f}));
}

TEST(Camera, BadCameraFilesNameTheKey) {
  const auto expect_error = [](const std::string& json, const std::string& word) {
    try {
      cg::parse_camera(json, "cam.json");
      ADD_FAILURE() << "accepted: " << json;
    } catch (const cg::ParamError& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what() << " should name " << word;
    }
  };
  expect_error("{}", "camera_to_cloud");
  expect_error(camera_json({0, 0, 0}, 0.5, 0.5, 0, 10), "resolution");
  expect_error(camera_json({0, 0, 0}, -1, 0.5, 10, 10), "tan_half_fov");
  expect_error(
      "{\"camera_to_cloud\": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], \"tan_half_fov\": [1,1],"
      " \"resolution\": [8,8]}",
      "rigid");
  expect_error(camera_json({0, 0, 0}, 0.5, 0.5, 8, 8, ", \"type\": \"ORTHO\""), "perspective");
  expect_error(camera_json({0, 0, 0}, 0.5, 0.5, 8, 8, ", \"light_directions\": [[0,0,0]]"), "light_directions");
  expect_error(camera_json({0, 0, 0}, 0.5, 0.5, 8, 8, ", \"zoom\": 2"), "zoom");
  expect_error("[1, 2]", "object");
}

}  // namespace
