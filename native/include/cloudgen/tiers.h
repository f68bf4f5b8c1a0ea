// cloudgen/tiers.h — quality tiers: named points on the measured speed/accuracy
// trade (native/presets/tiers.json, compiled in; bench/accuracy measures them).
//
// A tier fixes the knobs a user trades speed for accuracy with: Cycles samples
// and volume step rate for rendering, resolution / LOD / drop tolerance /
// half floats for baking, and the 2D preview's size. A tier's optional
// "measured" object (the benchmark's figures per scene: times and errors) is
// checked to be an object but not kept here: the add-on and the docs read it
// from tiers_json().
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "cloudgen/camera.h"

namespace cg {

struct Tier {
  std::string name, label, description;
  int render_samples = 64;
  float render_step_rate = 1.0f;
  int bake_resolution = 128;
  bool bake_lod = true;
  float bake_tolerance = 0.0f;
  bool bake_half = false;
  float bake_pixels_per_voxel = kDefaultPixelsPerVoxel;  // camera-aware bakes: voxel edge in pixel footprints
  int preview_size = 256;
};

// The tiers in the data file's order (Draft, Preview, Final).
const std::vector<Tier>& tiers();
// Parse a tiers file; throws ParamError naming the tier and key of a bad value.
std::vector<Tier> parse_tiers(std::string_view text);
// nullptr when there is no such tier.
const Tier* find_tier(std::string_view name);
// The data file's text (key order kept) for the add-on and the docs.
const char* tiers_json();

}  // namespace cg
