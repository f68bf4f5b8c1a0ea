// cloudgen/model.h — the C++ evaluator of the shared cloud model.
//
// prepare() turns validated user parameters into the physical, per-cloud
// constants the kernel needs (mapping sliders, computing frequencies and the
// wrapped noise offsets). density() evaluates eq. 3.4 at one point, in the
// same order of operations as the OSL shaders (osl/), so both give the same
// numbers. Everything here is pure: no I/O, no allocation, no globals.
#pragma once

#include "cloudgen/params.h"
#include "cloudgen/shared/cloud_model.h"

namespace cg {

// The fields are the rows of model_fields.h (the same rows make the field key).
struct Model {
#define CG_MODEL_FIELD(type, name, key_rule) type name;
#define CG_MODEL_ARRAY(type, name, count, key_rule) type name[count];
#include "cloudgen/model_fields.h"
#undef CG_MODEL_ARRAY
#undef CG_MODEL_FIELD
};

// Octaves each noise may evaluate (level of detail); kNoLod evaluates all.
struct Lod {
  float worley_octaves = CG_MAX_OCTAVES;
  float perlin_octaves = CG_MAX_OCTAVES;
};
inline constexpr Lod kNoLod{};

// The kernel's safe domain: prepare() accepts any finite values (also beyond
// the declared limits — the tests call it that way) and never yields NaN/Inf.
Model prepare(const Params& params);

// LOD for sampling with step `footprint` (scene units); 0 = no limit.
Lod lod_for_footprint(const Model& m, float footprint);

// Generated (box) coordinates of a local point: p / box + 1/2.
inline vec3 generated(const Model& m, vec3 p) {
  return {p[0] / m.box[0] + 0.5f, p[1] / m.box[1] + 0.5f, p[2] / m.box[2] + 0.5f};
}

inline bool inside_box(vec3 g) {
  return g[0] >= 0.0f && g[0] <= 1.0f && g[1] >= 0.0f && g[1] <= 1.0f && g[2] >= 0.0f && g[2] <= 1.0f;
}

// Shape term at generated coordinates g: the curve (if used) is evaluated here.
inline float shape_at_generated(const Model& m, vec3 g) {
  const float curve_value =
      m.shape_mode == 1 ? cg_curve_eval(m.curve, cg_shape_height(g[2], m.cloud_scale, m.base_height, m.top_height))
                        : 0.0f;
  return cg_shape(g, m.cloud_scale, m.shape_mode, m.shape_exponent, curve_value, m.base_height, m.top_height, m.lean,
                  m.sheet, m.anvil, m.anvil_height);
}

// Shape term (S(h) - T_x^2 - T_y^2 with the shape terms) at a local point.
inline float shape_at(const Model& m, vec3 p) { return shape_at_generated(m, generated(m, p)); }

// The local point moved by the domain warp (the identity at Warp 0).
inline vec3 warped(const Model& m, vec3 p) {
  return cg_domain_warp(p, m.warp, m.warp_frequency, p * m.warp_frequency + m.warp_offset, m.w4, m.seed);
}

// Cloud Noise texture N in [0, 1] at a local point.
inline float noise_at(const Model& m, vec3 p, const Lod& lod = kNoLod) {
  const vec3 q = cg_noise_warp(warped(m, p), m.stretch, m.shear);
  const vec3 pw = q * m.worley_frequency + m.worley_offset;
  const vec3 pp = q * m.perlin_frequency + m.perlin_offset;
  const vec3 pt = cg_turret_point(q, m.turret_frequency, m.turret_offset);
  return cg_cloud_noise(pw, pp, pt, m.w4, m.worley_influence, m.worley_clump, m.wave, m.noise_influence, m.noise_detail,
                        m.noise_whisp, m.fibres, m.turret_influence, lod.worley_octaves, lod.perlin_octaves, m.seed);
}

// The distortion F at generated coordinates g: F x the anvil's calm (F itself at Anvil 0).
inline float distortion_at_generated(const Model& m, vec3 g) {
  const float hl = cg_shape_height(g[2], m.cloud_scale, m.base_height, m.top_height);
  return m.distortion * cg_anvil_calm(hl, m.anvil, m.anvil_height, m.top_height);
}

// The edge width at generated coordinates g: widened in the anvil (the edge width itself at Anvil 0).
inline float edge_width_at_generated(const Model& m, vec3 g) {
  const float hl = cg_shape_height(g[2], m.cloud_scale, m.base_height, m.top_height);
  return cg_anvil_edge_width(m.edge_width, hl, m.anvil, m.anvil_height, m.top_height);
}

// The shape term less the anvil's fibre gaps (the shape itself at Anvil Fibres 0): what eq. 3.4
// adds the distortion to, once the shape alone has not proved the point empty.
inline float fibred_shape_at_generated(const Model& m, vec3 g, float shape) {
  return shape - cg_anvil_fibre_cut(g, m.cloud_scale, m.base_height, m.top_height, m.lean, m.anvil, m.anvil_height,
                                    m.anvil_fibres);
}

// Density at a local point: 0 outside the box and wherever the shape proves
// it empty (no noise evaluated there; the proof uses |F|, which bounds the calmed F
// too, and the shape before the anvil's fibre gaps, which only lower it), else
// eq. 3.4 clamped at 0 × Density.
inline float density(const Model& m, vec3 p, const Lod& lod = kNoLod) {
  const vec3 g = generated(m, p);
  if (!inside_box(g)) return 0.0f;
  const float s = shape_at_generated(m, g);
  if (cg_shape_proves_empty(s, m.distortion)) return 0.0f;
  return cg_cloud_main(fibred_shape_at_generated(m, g, s), noise_at(m, p, lod), distortion_at_generated(m, g),
                       m.density, edge_width_at_generated(m, g));
}

// An upper bound of the unscaled density (shape + |F|/2) over the axis-aligned
// region [lo, hi] of local space. <= 0 proves every point of it empty.
float shape_upper_bound(const Model& m, vec3 lo, vec3 hi);

}  // namespace cg
