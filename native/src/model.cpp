// model.cpp — prepare() and the region bound used to skip provably empty space.
#include "cloudgen/model.h"

#include <algorithm>
#include <cmath>

namespace cg {

namespace {

float finite_clamp(float v, float lo, float hi) { return std::clamp(v, lo, hi); }

// Largest squared value |t|^2 can take its minimum at over [a, b].
float min_square(float a, float b) {
  if (a <= 0.0f && b >= 0.0f) return 0.0f;
  return std::min(a * a, b * b);
}

// Maximum of the profile's core (no outside fall-off) over [a, b] ⊂ [0, 1].
float core_max(const Model& m, float a, float b) {
  if (m.shape_mode == 1) {
    float best = std::max(cg_curve_eval(m.curve, a), cg_curve_eval(m.curve, b));
    for (int i = 0; i < CG_CURVE_POINTS; ++i) {
      const float h = float(i) / float(CG_CURVE_POINTS - 1);
      if (h > a && h < b) best = std::max(best, m.curve[i]);
    }
    return best;
  }
  // 1 - u^2 with u = 2 h^e - 1 increasing in h: the largest value is where |u| is smallest.
  const float e = std::clamp(m.shape_exponent, CG_EXPONENT_MIN, CG_EXPONENT_MAX);
  const float ua = 2.0f * pow(a, e) - 1.0f;
  const float ub = 2.0f * pow(b, e) - 1.0f;
  return 1.0f - min_square(ua, ub);
}

}  // namespace

Model prepare(const Params& p) {
  Model m{};
  for (int i = 0; i < 3; ++i) m.box[i] = finite_clamp(std::fabs(p.get(BOX_SIZE, i)), 1e-6f, 1e9f);
  m.cloud_scale = p.get(CLOUD_SCALE);
  m.shape_mode = p.get(SHAPE_MODE) >= 0.5f ? 1 : 0;
  m.shape_exponent = p.get(SHAPE_EXPONENT);
  for (int i = 0; i < CG_CURVE_POINTS; ++i) m.curve[i] = finite_clamp(p.get(SHAPE_CURVE, i), -1e6f, 1e6f);
  m.distortion = finite_clamp(p.get(DISTORTION), -1e6f, 1e6f);
  m.density = finite_clamp(p.physical(DENSITY), 0.0f, 1e6f);

  const float overall = p.get(OVERALL_SCALE);
  m.worley_frequency = cg_worley_frequency(overall);
  m.perlin_frequency = cg_perlin_frequency(overall, p.get(NOISE_SCALE));

  const vec3 location = p.vector(OBJECT_LOCATION);
  const vec3 wind = p.vector(WIND_DIRECTION);
  const float stationary = p.get(STATIONARY);
  const float strength = p.physical(WIND_STRENGTH);
  const float time = p.get(TIME);
  m.worley_offset = cg_noise_offset(location, stationary, wind, strength, time, m.worley_frequency);
  m.perlin_offset = cg_noise_offset(location, stationary, wind, strength, time, m.perlin_frequency);
  m.w4 = cg_noise_time(time, p.get(EVOLUTION));

  m.worley_influence = p.get(WORLEY_INFLUENCE);
  m.worley_clump = p.get(WORLEY_CLUMP);
  m.wave = p.get(WAVE);
  m.noise_influence = p.get(NOISE_INFLUENCE);
  m.noise_detail = p.get(NOISE_DETAIL);
  m.noise_whisp = p.get(NOISE_WHISP);
  m.fibres = p.get(FIBRES);
  m.seed = static_cast<int>(finite_clamp(p.get(SEED), -1073741824.0f, 1073741824.0f));

  m.edge_width = cg_edge_width(p.get(EDGE_SHARPNESS));
  m.base_height = p.get(BASE_HEIGHT);
  m.top_height = p.get(TOP_HEIGHT);
  m.lean = p.get(LEAN);
  m.sheet = p.get(SHEET);
  m.anvil = p.get(ANVIL);
  m.anvil_height = p.get(ANVIL_HEIGHT);
  m.anvil_fibres = p.get(ANVIL_FIBRES);
  m.stretch = p.get(STRETCH);
  m.shear = p.get(SHEAR);
  m.warp = p.get(WARP);
  m.warp_frequency = cg_warp_frequency(m.worley_frequency, p.get(WARP_SCALE));
  m.warp_offset = cg_noise_offset(location, stationary, wind, strength, time, m.warp_frequency);
  m.turret_influence = p.get(TURRET_INFLUENCE);
  m.turret_frequency = cg_turret_frequency(m.worley_frequency, p.get(TURRET_SCALE));
  m.turret_offset = cg_turret_offset(location, stationary, wind, strength, time, m.turret_frequency);
  return m;
}

Lod lod_for_footprint(const Model& m, float footprint) {
  return {cg_lod_octaves(m.worley_frequency, footprint), cg_lod_octaves(m.perlin_frequency, footprint)};
}

namespace {

// Smallest value of the horizontal term cg_horizontal(t, sheet) over t in [a, b]: the term
// grows with |t|, so it is the term at the t of smallest |t|.
float min_horizontal(float a, float b, float sheet) {
  const float t = (a <= 0.0f && b >= 0.0f) ? 0.0f : (std::fabs(a) < std::fabs(b) ? a : b);
  return cg_horizontal(t, sheet);
}

// The interval of k t over t in [a, b] and k in [k1, k2] (k > 0): the product is monotone in each, so
// its extremes are at the corners.
void scaled_interval(float a, float b, float k1, float k2, float& lo, float& hi) {
  lo = std::min(std::min(a * k1, a * k2), std::min(b * k1, b * k2));
  hi = std::max(std::max(a * k1, a * k2), std::max(b * k1, b * k2));
}

}  // namespace

float shape_upper_bound(const Model& m, vec3 lo, vec3 hi) {
  float t_lo[3], t_hi[3];
  const float inv = 1.0f / std::clamp(std::fabs(m.cloud_scale), CG_CLOUD_SCALE_MIN, CG_CLOUD_SCALE_MAX);
  for (int i = 0; i < 3; ++i) {
    const float half = 0.5f * m.box[i];
    const float a = std::max(lo[i], -half), b = std::min(hi[i], half);
    if (a > b) return -1.0f;  // no part of the region is inside the box
    // T = (2G - 1) / cloud_scale = 2 p / box / cloud_scale, increasing in p
    t_lo[i] = 2.0f * (a / m.box[i]) * inv;
    t_hi[i] = 2.0f * (b / m.box[i]) * inv;
  }
  // h over the region (unclamped), then the profile's height h_l = clamp(h, base, top) (monotone)
  const float ha = (t_lo[2] + 1.0f) * 0.5f, hb = (t_hi[2] + 1.0f) * 0.5f;
  const float base = std::clamp(m.base_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT);
  const float top = std::clamp(m.top_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT);
  const float hl_lo = std::clamp(std::min(std::max(ha, base), top), 0.0f, 1.0f);
  const float hl_hi = std::clamp(std::min(std::max(hb, base), top), 0.0f, 1.0f);
  // the floor/ceiling penalty is at least its value at the region's best end of each part
  const float penalty = float(CG_FLOOR_FALLOFF) * (std::max(base - hb, 0.0f) + std::max(ha - top, 0.0f));
  // lean: T_x' = T_x - lean h_c^2, h_c^2 over [hc_lo^2, hc_hi^2]
  const float lean = std::clamp(m.lean, -CG_LEAN_LIMIT, CG_LEAN_LIMIT);
  const float hc_lo = std::clamp(ha, 0.0f, 1.0f), hc_hi = std::clamp(hb, 0.0f, 1.0f);
  const float s_lo = hc_lo * hc_lo, s_hi = hc_hi * hc_hi;
  const float shift_max = std::max(lean * s_lo, lean * s_hi), shift_min = std::min(lean * s_lo, lean * s_hi);
  // anvil: both T scaled by k(h_l) (h_l not clamped to [0, 1] here, as in the kernel), non-increasing in h_l
  const float k_min = cg_anvil_narrowing(std::min(std::max(hb, base), top), m.anvil, m.anvil_height, m.top_height);
  const float k_max = cg_anvil_narrowing(std::min(std::max(ha, base), top), m.anvil, m.anvil_height, m.top_height);
  float tx_lo, tx_hi, ty_lo, ty_hi;
  scaled_interval(t_lo[0] - shift_max, t_hi[0] - shift_min, k_min, k_max, tx_lo, tx_hi);
  scaled_interval(t_lo[1], t_hi[1], k_min, k_max, ty_lo, ty_hi);
  // the sheet's cap is non-decreasing in h: at least its value at the region's lowest h
  const float cap = cg_sheet_cap(ha, m.sheet);
  const float s_max = core_max(m, hl_lo, hl_hi) - penalty - cap - min_horizontal(tx_lo, tx_hi, m.sheet) -
                      min_horizontal(ty_lo, ty_hi, m.sheet);
  // 1e-4 (relative to the largest term) absorbs the rounding differences between this bound and the kernel
  const float scale = 1.0f + penalty + cap + tx_lo * tx_lo + tx_hi * tx_hi + ty_lo * ty_lo + ty_hi * ty_hi;
  return s_max + 0.5f * std::fabs(m.distortion) + 1e-4f * scale;
}

}  // namespace cg
