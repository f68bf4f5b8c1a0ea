// cloudgen/camera.h — what a camera can see of a cloud: the camera-aware bake.
//
// A CameraView is a perspective camera in the cloud's local frame (scene
// units, origin at the box centre, axes along the box sides; the camera looks
// along its -Z with +Y up, Blender's convention). fit_camera() derives from it
// the voxel size the image can resolve — the footprint of one pixel at the
// nearest visible point of the box — and the region worth baking: the view
// frustum widened by a margin, because cloud just outside the view still
// shadows and lights what is inside it.
#pragma once

#include <array>
#include <string_view>

#include "cloudgen/model.h"

namespace cg {

// Voxel edge in pixel footprints: the accepted range and the value when
// neither the camera file nor a quality tier sets one (tiers.json, camera.json).
inline constexpr double kMinPixelsPerVoxel = 0.01, kMaxPixelsPerVoxel = 1e4;
inline constexpr float kDefaultPixelsPerVoxel = 1.0f;

struct CameraView {
  double camera_to_cloud[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};  // row-major, rigid
  float tan_half_fov[2] = {0.36f, 0.27f};                                                   // horizontal, vertical
  int resolution[2] = {320, 240};                                                           // image pixels
  float near_clip = 0.1f;         // scene units in front of the camera
  float margin = -1.0f;           // scene units; < 0: default_margin()
  float pixels_per_voxel = 0.0f;  // voxel edge in pixel footprints (0: kDefaultPixelsPerVoxel)
  int light_count = 0;            // directions towards the lights (sun), cloud frame
  std::array<vec3, 4> lights{};
};

// Reads the CAMERA.json object (docs/camera.md). Throws ParamError naming
// `origin` and the key of a missing or bad value (e.g. a non-rigid matrix).
CameraView parse_camera(std::string_view text, std::string_view origin = "camera");

// Plane n·p + d >= 0 is the inside; |n| = 1.
struct Plane {
  vec3 n;
  float d;
};

// The view frustum in the cloud's frame: four sides and the near plane, each
// pushed outwards by `widen` scene units (no far plane: clouds are far) —
// and, with lights, the frustum swept towards each light: what lies between
// a visible point and a light shadows it, however far outside the view.
struct Frustum {
  std::array<Plane, 5> planes;
  int light_count = 0;
  std::array<vec3, 4> lights{};  // unit directions towards the lights
};
Frustum view_frustum(const CameraView& c, float widen);

// True when no point of the box [lo, hi] is in the frustum or between a
// point of it and a light (conservative: may say false for boxes outside).
bool box_outside(const Frustum& f, vec3 lo, vec3 hi);

// Margin around the view for light scattered (and, without light directions,
// shadowed) from outside it: the distance over which a quarter of the cloud's
// peak extinction (Density × 20 per scene unit) reaches optical depth 4
// (transmittance e^-4 ≈ 2 %), i.e. 16 / extinction, at most the longest box
// side. docs/camera.md has the measurements behind it.
float default_margin(const Model& m);

struct CameraFit {
  bool visible = false;     // some of the box is inside the (un-widened) frustum
  float nearest_depth = 0;  // smallest view depth of a visible box point (>= near_clip)
  float footprint = 0;      // one pixel's size at that depth, scene units
  float voxel = 0;          // footprint × pixels_per_voxel (not visible: the longest box side)
  float margin = 0;         // the margin used
  Frustum region;           // the frustum widened by the margin: tiles outside it are not baked
                            // (not visible: a region nothing passes)
};
CameraFit fit_camera(const Model& m, const CameraView& c);

}  // namespace cg
