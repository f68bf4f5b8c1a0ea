/* cloudgen/shared/cloud_model.h — the cloud density (thesis eq. 3.4) and the
 * Cloud Noise distortion texture, shared by C++ and OSL.
 *
 * Coordinates. `p` is a point in the cloud object's local frame, in scene
 * units: the origin at the box centre, axes along the box edges, the object's
 * scale already folded into `box` (the box dimensions). The shape uses the
 * generated coordinates G = p / box + 1/2 in [0,1]^3; the noise uses p itself
 * (so it does not stretch with the box) plus a wrapped offset (Stationary,
 * wind × time) prepared by cg_noise_offset.
 *
 * Every formula, constant and bound is written out in docs/model.md.
 */
#ifndef CLOUDGEN_SHARED_CLOUD_MODEL_H
#define CLOUDGEN_SHARED_CLOUD_MODEL_H

#include "noise.h"

CG_NAMESPACE_BEGIN

#define CG_CURVE_POINTS 17                /* shape curve samples at h = 0, 1/16, ..., 1 */
#define CG_PROFILE_FALLOFF 16             /* S falls off as -16 (h - clamp(h))^2 below the base / above the top */
#define CG_DENSITY_SCALE 20               /* physical density = 20 x the Density slider, per scene unit */
#define CG_BASE_FREQUENCY CG_FLOAT(2.5)   /* Worley cells per scene unit at Overall Scale 1 */
#define CG_PERLIN_RELATIVE CG_FLOAT(2.0)  /* gradient-noise frequency / Worley frequency at Noise Scale 1 */
#define CG_WORLEY_OCTAVES 2               /* thesis 4.2: fixed at 2 */
#define CG_PERLIN_CONTRAST CG_FLOAT(1.0)  /* P01 = 1/2 + contrast * fBm */
#define CG_WAVE_FREQUENCY 1               /* sine periods per Worley cell along x */
#define CG_WAVE_WARP CG_FLOAT(0.75)       /* phase warp of the sine by the gradient fBm, in periods */
#define CG_FIBRE_SHARPNESS CG_FLOAT(12.0) /* Fibres: a fibre is where |P| < 1/12 (P, the gradient fBm) */
#define CG_TWO_PI CG_FLOAT(6.2831853)
#define CG_COORD_LIMIT CG_FLOAT(1.0e9) /* kernel clamp of offsets and times (finite in, finite out) */
#define CG_SEED_SALT_WORLEY 1597334677
/* Kernel clamps, shared with the region bound (model.cpp: shape_upper_bound, core_max) so that the bound
 * and the kernel evaluate the same profile. Wider than the declared parameter ranges: they only keep the
 * formulas finite (docs/model.md, "The kernel's safe domain"). */
#define CG_CLOUD_SCALE_MIN CG_FLOAT(0.001) /* |Cloud Scale| */
#define CG_CLOUD_SCALE_MAX CG_FLOAT(1000.0)
#define CG_EXPONENT_MIN CG_FLOAT(0.01) /* Shape Exponent */
#define CG_EXPONENT_MAX CG_FLOAT(100.0)
#define CG_NOISE_SCALE_MIN CG_FLOAT(0.0001) /* Overall Scale and Noise Scale */
#define CG_NOISE_SCALE_MAX CG_FLOAT(10000.0)
/* Shape terms beyond the thesis (docs/model.md, "Shape terms"). */
#define CG_EDGE_WIDTH_MIN CG_FLOAT(0.08)   /* edge width at Edge Sharpness 1, in units of the raw density */
#define CG_FLOOR_FALLOFF 500               /* the shape falls by 500 per unit of h below the base / above the top */
#define CG_HEIGHT_LIMIT CG_FLOAT(1000.0)   /* kernel clamp of Base Height and Top Height */
#define CG_LEAN_LIMIT CG_FLOAT(1000.0)     /* kernel clamp of Lean */
#define CG_SHEET_MARGIN CG_FLOAT(0.5)      /* a sheet fades over the outer half of its half-width */
#define CG_SHEET_FALLOFF 2                 /* the sheet's fade term where |T| = 1 (the cloud's edge) */
#define CG_SHEET_CAP_WIDTH CG_FLOAT(0.125) /* a sheet closes over the top eighth of its height ... */
#define CG_SHEET_CAP_DEPTH 2               /* ... its shape lowered by up to 2 there: empty at the top */
#define CG_ANVIL_SPREAD 4                  /* at Anvil 1 the shape below the anvil is narrowed 1 + 4 = 5 times */
#define CG_ANVIL_LIMIT CG_FLOAT(1000.0)    /* kernel clamp of Anvil */
#define CG_ANVIL_MIN_DEPTH CG_FLOAT(0.01)  /* the anvil's flare spans at least 1 % of the cloud's height */
#define CG_ANVIL_CALM CG_FLOAT(0.75)       /* at the ceiling the anvil's distortion is 1 - 0.75 = 1/4 of F */
#define CG_STRETCH_MAX CG_FLOAT(1.0e6)     /* kernel clamp of Stretch */
#define CG_SHEAR_LIMIT CG_FLOAT(1000.0)    /* kernel clamp of Shear */
#define CG_TURRET_SCALE_MIN CG_FLOAT(0.01) /* kernel clamp of Turret Size, in Worley cells */
#define CG_TURRET_SCALE_MAX CG_FLOAT(10000.0)
#define CG_TURRET_ASPECT CG_FLOAT(0.5) /* turret cells are 1 / 0.5 = 2 times taller than wide */
#define CG_SEED_SALT_TURRET 374761393
#define CG_WARP_LIMIT CG_FLOAT(100.0)    /* kernel clamp of Warp, in warp cells */
#define CG_WARP_SCALE_MIN CG_FLOAT(0.01) /* kernel clamp of Warp Size, in Worley cells */
#define CG_WARP_SCALE_MAX CG_FLOAT(10000.0)
#define CG_SEED_SALT_WARP_X 668265263
#define CG_SEED_SALT_WARP_Y 1013904223
/* Anvil Fibres (docs/model.md, "Anvil fibres"): streaks of ice in the anvil, a gradient noise read at the
 * horizontal direction from the anvil's axis (angular), the distance from it (radial) and the height. */
#define CG_ANVIL_FIBRE_DEPTH CG_FLOAT(0.3)     /* at Anvil Fibres 1 the gaps between fibres lower r by 0.3 */
#define CG_ANVIL_FIBRE_ANGULAR CG_FLOAT(5.0)   /* noise cells across one radian of direction (~30 around) */
#define CG_ANVIL_FIBRE_RADIAL CG_FLOAT(6.0)    /* noise cells per unit of the anvil's (narrowed) radius */
#define CG_ANVIL_FIBRE_VERTICAL CG_FLOAT(24.0) /* noise cells per unit of h: thin, nearly flat sheets */
#define CG_ANVIL_FIBRE_SHARPNESS CG_FLOAT(3.0) /* a fibre is where |n| < 1/3; clear from there */
#define CG_ANVIL_FIBRE_CORE_IN CG_FLOAT(0.25)  /* no fibres within this radius of the axis ... */
#define CG_ANVIL_FIBRE_CORE_OUT CG_FLOAT(0.55) /* ... all of them from this radius out (the rim) */
#define CG_ANVIL_FIBRE_ONSET CG_FLOAT(4.0)     /* full from a quarter of the way up the anvil (u = 1/4) */
#define CG_SEED_SALT_ANVIL_FIBRE 1274126177

/* ---------------------------------------------------------------- shape --- */

/* Piecewise-linear height curve, h in [0, 1]. */
CG_FN float cg_curve_eval(CG_IN_ARRAY curve[CG_CURVE_POINTS], float h) {
  float x = clamp(h, 0, 1) * (CG_CURVE_POINTS - 1);
  int i = int(floor(x));
  if (i > CG_CURVE_POINTS - 2) i = CG_CURVE_POINTS - 2;
  if (i < 0) i = 0;
  return mix(curve[i], curve[i + 1], x - i);
}

/* Height parameter of the profile: h = (T_z + 1) / 2 with T_z = (2 G_z - 1) / cloud_scale;
 * the cloud spans h in [0, 1]. */
CG_FN float cg_height(float gz, float cloud_scale) {
  float inv = 1 / clamp(fabs(cloud_scale), CG_CLOUD_SCALE_MIN, CG_CLOUD_SCALE_MAX);
  return ((2 * gz - 1) * inv + 1) / 2;
}

/* Height profile S(h): the squared radius of the body of revolution at height
 * h (thesis 3.1.2/3.1.3). mode 0: exponent, S = 1 - (2 h^e - 1)^2 (the
 * ellipsoid with its height axis bent by h^e); mode 1: `curve_value`, the
 * height curve evaluated at clamp(h, 0, 1) by the caller (C++: cg_curve_eval
 * on the 17 samples; Blender: a Float Curve node with vector handles through
 * the same samples, feeding the Shape Gradient socket). Outside [0, 1] the
 * profile falls off as -CG_PROFILE_FALLOFF (h - clamp(h))^2: four times
 * steeper than the ellipsoid would continue, so that billows do not hang
 * below a flat cloud base. */
CG_FN float cg_profile(float h, int mode, float exponent, float curve_value) {
  float hc = clamp(h, 0, 1);
  float core = curve_value;
  if (mode != 1) {
    float u = 2 * pow(hc, clamp(exponent, CG_EXPONENT_MIN, CG_EXPONENT_MAX)) - 1;
    core = 1 - u * u;
  }
  float out = h - hc;
  return core - CG_PROFILE_FALLOFF * out * out;
}

/* The height at which the profile is read: h held inside [base, top] (the flat
 * floor and ceiling; with the defaults -0.5 and 1.5 every point of the cloud
 * has h inside, so this is h). The Shape Gradient curve is evaluated here too. */
CG_FN float cg_shape_height(float gz, float cloud_scale, float base_height, float top_height) {
  float b = clamp(base_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT);
  float t = clamp(top_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT);
  return clamp(cg_height(gz, cloud_scale), b, t);
}

/* Below the base and above the top the shape falls linearly and steeply
 * (CG_FLOOR_FALLOFF per unit of h): a flat floor / ceiling that the profile
 * and the noise (S + |F|/2, at most 2 in the declared ranges) push through by
 * at most 2 / 500 = 0.4 % of the cloud's height. */
CG_FN float cg_floor_penalty(float h, float base_height, float top_height) {
  float b = clamp(base_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT);
  float t = clamp(top_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT);
  return CG_FLOOR_FALLOFF * (max(b - h, 0) + max(h - t, 0));
}

/* Horizontal term of one axis: T^2 for a body of revolution (Sheet 0); for a
 * sheet (Sheet 1) 0 in the middle and a fade over the outer CG_SHEET_MARGIN
 * of the half-width, CG_SHEET_FALLOFF at |T| = 1; in between a blend. Both
 * parts grow with |T|. */
CG_FN float cg_horizontal(float t, float sheet) {
  float k = clamp(sheet, 0, 1);
  if (k > 0) {
    float e = max(fabs(t) - (1 - CG_SHEET_MARGIN), 0) / CG_SHEET_MARGIN;
    return (1 - k) * (t * t) + k * (CG_SHEET_FALLOFF * (e * e));
  }
  return t * t;
}

/* A sheet's cap: how far its shape is lowered near the top of its box, sheet x CG_SHEET_CAP_DEPTH x
 * u^2 with u = (h - (1 - CG_SHEET_CAP_WIDTH)) / CG_SHEET_CAP_WIDTH clamped to [0, 1]. A sheet keeps
 * its profile up to the top (h = 1, the box's top face at Cloud Scale 1), where a profile of 0 still
 * leaves cloud wherever the noise is below 1/2 (about 43 % of the face): the box cut the cells off
 * flat, a hard lid. Lowered by 2 at h = 1 (the profile is at most 1 and |F| / 2 at most 1 in the
 * declared ranges) the top face of a full sheet is provably empty; the quadratic starts level, so
 * the cells close over the top eighth in rounded tops. Non-decreasing in h, so a bound taken at the
 * lowest h of a region holds; exactly 0 at Sheet 0 (compact clouds unchanged bit for bit). */
CG_FN float cg_sheet_cap(float h, float sheet) {
  float k = clamp(sheet, 0, 1);
  if (k > 0) {
    float u = clamp((h - (1 - CG_SHEET_CAP_WIDTH)) / CG_SHEET_CAP_WIDTH, 0, 1);
    return k * CG_SHEET_CAP_DEPTH * (u * u);
  }
  return 0;
}

/* The x shape coordinate leaned downwind (+x) with height: T_x - lean h_c^2. */
CG_FN float cg_lean_x(float tx, float h, float lean) {
  float hc = clamp(h, 0, 1);
  return tx - clamp(lean, -CG_LEAN_LIMIT, CG_LEAN_LIMIT) * (hc * hc);
}

/* The anvil's narrowing factor k(h_l) >= 1 by which the horizontal shape
 * coordinates are multiplied: k = 1 + 4 anvil (1 - u)^2, u = (h_l - a) / (c - a)
 * clamped to [0, 1], with a the Anvil Height (in [0, 1]) and c the ceiling
 * min(top, 1) (at least a + 0.01). Below a the whole shape is narrowed k times
 * (the tower); from a to the ceiling the narrowing fades out, fast at first
 * (a thick anvil with a sloping underside) and level at the ceiling (a rounded
 * lip), so the anvil spreads to the curve's full radius. The tower keeps the
 * curve's core value and with it its crisp edge and billows (a thin tower made
 * by the curve alone has a core of r^2, which the noise erodes). Non-increasing
 * in h_l; exactly 1 at Anvil 0. */
CG_FN float cg_anvil_u(float hl, float anvil_height, float top_height) {
  float a = clamp(anvil_height, 0, 1);
  float c = max(min(clamp(top_height, -CG_HEIGHT_LIMIT, CG_HEIGHT_LIMIT), CG_FLOAT(1.0)), a + CG_ANVIL_MIN_DEPTH);
  return clamp((hl - a) / (c - a), 0, 1);
}

CG_FN float cg_anvil_narrowing(float hl, float anvil, float anvil_height, float top_height) {
  float u = cg_anvil_u(hl, anvil_height, top_height);
  return 1 + CG_ANVIL_SPREAD * clamp(anvil, 0, CG_ANVIL_LIMIT) * ((1 - u) * (1 - u));
}

/* How far the anvil's calm and soft edge are on: min(4 anvil, 1), full from Anvil 0.25, 0 at Anvil 0. */
CG_FN float cg_anvil_on(float anvil) { return min(CG_ANVIL_SPREAD * clamp(anvil, 0, CG_ANVIL_LIMIT), CG_FLOAT(1.0)); }

/* The anvil's calm: the factor of the distortion F at height h_l, 1 - 0.75 u min(4 anvil, 1).
 * An anvil is ice spread flat under the tropopause: its top is smooth, not billowed like the
 * tower, so the billows fade from the Anvil Height to a quarter at the ceiling. Exactly 1 at
 * Anvil 0 and below the Anvil Height; in (0, 1], so |F| still bounds the distortion term. */
CG_FN float cg_anvil_calm(float hl, float anvil, float anvil_height, float top_height) {
  return 1 - CG_ANVIL_CALM * cg_anvil_u(hl, anvil_height, top_height) * cg_anvil_on(anvil);
}

/* The anvil's soft edge: the edge width w widened toward 1 (the thesis's ramp) with the anvil's
 * height, w + (1 - w) u min(4 anvil, 1). An anvil is ice, optically far thinner than the
 * water tower under it, and thins out toward its rim: with the ramp its density follows the shape
 * value, so the anvil fades over its whole spread instead of ending in a hard, rounded lip.
 * Exactly w at Anvil 0 and below the Anvil Height; in [w, 1], and the density is non-increasing
 * in the edge width, so every bound made at w still holds. */
CG_FN float cg_anvil_edge_width(float edge_width, float hl, float anvil, float anvil_height, float top_height) {
  float w = clamp(edge_width, CG_EDGE_WIDTH_MIN, 1);
  return w + (1 - w) * (cg_anvil_u(hl, anvil_height, top_height) * cg_anvil_on(anvil));
}

/* The horizontal shape coordinates (k T_x', k T_y, 0) at generated coordinates g: T = (2G - 1) /
 * cloud_scale, T_x' leaned downwind with the height, both multiplied by the anvil's narrowing k. */
CG_FN CG_VEC3 cg_anvil_coords(CG_VEC3 g, float cloud_scale, float lean, float k) {
  float inv = 1 / clamp(fabs(cloud_scale), CG_CLOUD_SCALE_MIN, CG_CLOUD_SCALE_MAX);
  float tx = cg_lean_x((2 * g[0] - 1) * inv, cg_height(g[2], cloud_scale), lean) * k;
  float ty = (2 * g[1] - 1) * inv * k;
  return CG_VEC3(tx, ty, 0);
}

/* Anvil Fibres: how much the raw value r of eq. 3.4 is lowered at generated coordinates g, in
 * [0, CG_ANVIL_FIBRE_DEPTH]: 0 on thin, nearly flat sheets of ice that run out radially from the
 * anvil's (leaned) axis and in the gaps between them up to depth x anvil_fibres x min(4 u, 1) x
 * min(4 anvil, 1) (u: how far up the anvil, cg_anvil_u) x the rim's weight (0 within
 * CG_ANVIL_FIBRE_CORE_IN of the axis, 1 from CG_ANVIL_FIBRE_CORE_OUT): the anvil's rim breaks into
 * streaks while its flat top and the middle stay smooth. Nothing below the Anvil Height, at Anvil 0
 * or Anvil Fibres 0 (no noise evaluated). The noise is one gradient octave plus a half-weight
 * octave at twice the frequency, read at (direction x angular, radius x radial, h_l x vertical)
 * in the anvil's own shape coordinates (fixed seed: the fibres belong to the shape and travel with
 * it). Lowering r never raises the density, so every emptiness proof still holds. */
CG_FN float cg_anvil_fibre_cut(CG_VEC3 g, float cloud_scale, float base_height, float top_height, float lean,
                               float anvil, float anvil_height, float anvil_fibres) {
  float af = clamp(anvil_fibres, 0, 1);
  if (af <= 0) return 0;
  float hl = cg_shape_height(g[2], cloud_scale, base_height, top_height);
  float weight =
      af * min(CG_ANVIL_FIBRE_ONSET * cg_anvil_u(hl, anvil_height, top_height), CG_FLOAT(1.0)) * cg_anvil_on(anvil);
  if (weight <= 0) return 0;
  CG_VEC3 t = cg_anvil_coords(g, cloud_scale, lean, cg_anvil_narrowing(hl, anvil, anvil_height, top_height));
  float tx = t[0];
  float ty = t[1];
  float radius = sqrt(tx * tx + ty * ty);
  float core = smoothstep(CG_ANVIL_FIBRE_CORE_IN, CG_ANVIL_FIBRE_CORE_OUT, radius);
  if (core <= 0) return 0;
  float a = CG_ANVIL_FIBRE_ANGULAR / radius; /* radius > 0 here */
  float x = tx * a;
  float y = ty * a;
  float z = radius * CG_ANVIL_FIBRE_RADIAL;
  float w = hl * CG_ANVIL_FIBRE_VERTICAL;
  float n = (cg_perlin4(x, y, z, w, CG_SEED_SALT_ANVIL_FIBRE) +
             CG_FLOAT(0.5) * cg_perlin4(2 * x, 2 * y, 2 * z, 2 * w, CG_SEED_SALT_ANVIL_FIBRE ^ 1)) /
            CG_FLOAT(1.5);
  float gap = min(fabs(n) * CG_ANVIL_FIBRE_SHARPNESS, CG_FLOAT(1.0));
  return CG_ANVIL_FIBRE_DEPTH * weight * core * gap;
}

/* Shape term of eq. 3.4 with the shape terms: S(h_l) - floor - cap - H(k T_x') - H(k T_y)
 * with T = (2G - 1) / cloud_scale, h_l = cg_shape_height, T_x' leaned, k the
 * anvil's narrowing. At the defaults (base -0.5, top 1.5, lean 0, sheet 0,
 * anvil 0) this is S(h) - T_x^2 - T_y^2 bit for bit wherever the density can
 * be > 0. `curve_value` is the curve at clamp(h_l, 0, 1) (mode 1). */
CG_FN float cg_shape(CG_VEC3 g, float cloud_scale, int mode, float exponent, float curve_value, float base_height,
                     float top_height, float lean, float sheet, float anvil, float anvil_height) {
  float h = cg_height(g[2], cloud_scale);
  float hl = cg_shape_height(g[2], cloud_scale, base_height, top_height);
  CG_VEC3 t = cg_anvil_coords(g, cloud_scale, lean, cg_anvil_narrowing(hl, anvil, anvil_height, top_height));
  float tx = t[0];
  float ty = t[1];
  float s = cg_profile(hl, mode, exponent, curve_value) - cg_floor_penalty(h, base_height, top_height) -
            cg_sheet_cap(h, sheet);
  return s - cg_horizontal(tx, sheet) - cg_horizontal(ty, sheet);
}

/* The distortion term F (1 - O) with O = N + 1/2 lies in [-|F|/2, |F|/2]; where
 * the shape alone is at most -|F|/2 the density is provably 0. */
CG_FN int cg_shape_proves_empty(float shape, float distortion) { return shape + fabs(distortion) / 2 <= 0; }

/* Edge Sharpness s in [0, 1] as the edge width w = 0.08^s (1 at s = 0). The smallest width, 0.08,
 * is 1-2 % of a cloud's size and keeps the slope 1/w (which multiplies any rounding difference of
 * r between OSL and C++, measured up to 6e-6) at 12.5: the parity of 1e-4 of the range holds. */
CG_FN float cg_edge_width(float edge_sharpness) { return pow(CG_EDGE_WIDTH_MIN, clamp(edge_sharpness, 0, 1)); }

/* The sharp boundary: the raw value r >= 0 of eq. 3.4 remapped to
 * min(r / w, max(r, 1)) — it reaches 1 (a cloud's core) within r = w instead
 * of r = 1, and keeps r above 1. w = 1 gives r exactly (the thesis's ramp). */
CG_FN float cg_edge(float r, float edge_width) {
  float w = clamp(edge_width, CG_EDGE_WIDTH_MIN, 1);
  return min(r / w, max(r, 1));
}

/* Cloud Main, eq. 3.4 with O = N + 1/2: D = E(max(S - T_x^2 - T_y^2 + F (1/2 - N), 0)) * density,
 * E the edge remap (identity at edge width 1), density clamped at 0. */
CG_FN float cg_cloud_main(float shape, float noise, float distortion, float density, float edge_width) {
  return cg_edge(max(shape + distortion * (CG_FLOAT(0.5) - noise), 0), edge_width) * max(density, 0);
}

/* ------------------------------------------------------------ frequencies --- */

/* Worley lattice cells per scene unit. */
CG_FN float cg_worley_frequency(float overall_scale) {
  return CG_BASE_FREQUENCY * clamp(overall_scale, CG_NOISE_SCALE_MIN, CG_NOISE_SCALE_MAX);
}

/* Gradient-noise lattice cells per scene unit. */
CG_FN float cg_perlin_frequency(float overall_scale, float noise_scale) {
  return cg_worley_frequency(overall_scale) * CG_PERLIN_RELATIVE *
         clamp(noise_scale, CG_NOISE_SCALE_MIN, CG_NOISE_SCALE_MAX);
}

/* Level of detail: how many octaves of a noise with base `frequency` (cells
 * per scene unit, lacunarity 2) a sampling step `footprint` (scene units) can
 * hold — octave k is kept while its cell spans at least two steps, the last
 * one fades out. At least the first octave is always kept; footprint <= 0
 * means no limit. */
CG_FN float cg_lod_octaves(float frequency, float footprint) {
  if (footprint <= 0) return CG_MAX_OCTAVES;
  return clamp(1 + log2(CG_FLOAT(0.5) / (frequency * footprint)), 1, CG_MAX_OCTAVES);
}

/* ------------------------------------------------------------- animation --- */

/* Offset of the noise field, in noise-lattice units, reduced modulo the
 * lattice period: Stationary = 1 means the texture travels with the object, 0
 * that it stays fixed in the world; wind shifts it by -velocity * time. */
CG_FN CG_VEC3 cg_noise_offset(CG_VEC3 location, float stationary, CG_VEC3 wind_direction, float wind_strength,
                              float time, float frequency) {
  /* unit direction, computed from the direction scaled by its largest component
   * so that neither tiny nor huge directions under- or overflow */
  float big = max(max(fabs(wind_direction[0]), fabs(wind_direction[1])), fabs(wind_direction[2]));
  CG_VEC3 unit = CG_VEC3(0, 0, 0);
  if (big > 0) {
    CG_VEC3 d = CG_VEC3(wind_direction[0] / big, wind_direction[1] / big, wind_direction[2] / big);
    float len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    unit = CG_VEC3(d[0] / len, d[1] / len, d[2] / len);
  }
  float travel = clamp(wind_strength, -CG_COORD_LIMIT, CG_COORD_LIMIT) * clamp(time, -CG_COORD_LIMIT, CG_COORD_LIMIT);
  float follow = 1 - clamp(stationary, 0, 1);
  CG_VEC3 o = CG_VEC3(0, 0, 0);
  for (int i = 0; i < 3; i += 1) {
    float c = clamp(location[i], -CG_COORD_LIMIT, CG_COORD_LIMIT) * follow - unit[i] * travel;
    o[i] = cg_wrap(c * frequency);
  }
  return o;
}

/* 4th noise coordinate: time × evolution speed, wrapped. */
CG_FN float cg_noise_time(float time, float evolution) {
  float t = clamp(time, -CG_COORD_LIMIT, CG_COORD_LIMIT);
  float e = clamp(evolution, -CG_COORD_LIMIT, CG_COORD_LIMIT);
  return cg_wrap(t * e);
}

/* ----------------------------------------------------------- cloud noise --- */

/* Which parts of Cloud Noise the (clamped) weights need: uniform over a
 * cloud, so the batched kernel (native/src/simd/) tests them once per block. */
CG_FN int cg_noise_uses_perlin(float wi, float wv, float ni) { return ni > 0 || (wi > 0 && wv > 0); }
CG_FN int cg_noise_uses_worley(float wi, float wv) { return wi > 0 && wv < 1; }
CG_FN int cg_noise_uses_sine(float wi, float wv) { return wi > 0 && wv > 0; }

/* The sine texture Sw at Worley x coordinate xw, phase-warped by P. */
CG_FN float cg_wave_sine(float xw, float p) {
  return CG_FLOAT(0.5) + CG_FLOAT(0.5) * sin(CG_TWO_PI * (CG_WAVE_FREQUENCY * xw + CG_WAVE_WARP * p));
}

/* Fibres: P mixed toward its ridged form R = 2 min(|P| s, 1) - 1 (s = CG_FIBRE_SHARPNESS), which is
 * -1 (dense) on the zero set of P and +1 (clear) wherever |P| >= 1/s: thin sheets through the
 * volume that Stretch draws out into filaments (cirrus). f = 0 is P itself; f is clamped to [0, 1]. */
CG_FN float cg_fibre_noise(float p, float fibres) {
  float f = clamp(fibres, 0, 1);
  if (f > 0) return mix(p, 2 * min(fabs(p) * CG_FIBRE_SHARPNESS, CG_FLOAT(1.0)) - 1, f);
  return p;
}

/* N from its parts (P, W, Sw; 1/2 stands for a part not needed) and the clamped weights
 * (fibres: the Fibres weight, clamped by cg_fibre_noise). */
CG_FN float cg_cloud_noise_combine(float p, float worley, float sine, float wi, float wv, float ni, float fibres) {
  float billow = CG_FLOAT(0.5);
  if (wi > 0) billow = mix(CG_FLOAT(0.5), mix(worley, sine, wv), wi);
  return clamp(billow * mix(1, 1 + 2 * CG_PERLIN_CONTRAST * cg_fibre_noise(p, fibres), ni), 0, 1);
}

/* The point the noise is read at: x stretched by 1 + Stretch (features that
 * long along the box's x axis) and sheared by Shear x z (features slanted
 * downwind with height: fall streaks, anvils). The identity at 0 and 0. */
CG_FN CG_VEC3 cg_noise_warp(CG_VEC3 p, float stretch, float shear) {
  float st = clamp(stretch, 0, CG_STRETCH_MAX);
  float sh = clamp(shear, -CG_SHEAR_LIMIT, CG_SHEAR_LIMIT);
  if (st > 0 || sh != 0) return CG_VEC3(p[0] / (1 + st) + sh * p[2], p[1], p[2]);
  return p;
}

/* Warp lattice cells per scene unit: one warp cell spans Warp Size Worley cells. */
CG_FN float cg_warp_frequency(float worley_frequency, float warp_scale) {
  return worley_frequency / clamp(warp_scale, CG_WARP_SCALE_MIN, CG_WARP_SCALE_MAX);
}

/* The domain warp: p moved horizontally by Warp warp cells times two single-octave gradient
 * noises of the warp lattice (each in [-1, 1]; `pw` is p in warp lattice units with its
 * wrapped offset, `w` the 4th coordinate). A smooth displacement a few times larger than the
 * billows bends every feature: curved fibres and hooks (cirrus), irregular lobes. Applied
 * before Stretch and Shear, so a fibre stretched along x waves across y. The identity at
 * Warp 0. */
CG_FN CG_VEC3 cg_domain_warp(CG_VEC3 p, float warp, float fwarp, CG_VEC3 pw, float w, int seed) {
  float a = clamp(warp, -CG_WARP_LIMIT, CG_WARP_LIMIT);
  if (a == 0) return p;
  float s = a / clamp(fwarp, CG_FLOAT(1.0e-6), CG_FLOAT(1.0e6));
  float dx = cg_perlin4(pw[0], pw[1], pw[2], w, seed ^ CG_SEED_SALT_WARP_X);
  float dy = cg_perlin4(pw[0], pw[1], pw[2], w, seed ^ CG_SEED_SALT_WARP_Y);
  return CG_VEC3(p[0] + s * dx, p[1] + s * dy, p[2]);
}

/* Turret lattice cells per scene unit (horizontally): Turret Size Worley cells per turret. */
CG_FN float cg_turret_frequency(float worley_frequency, float turret_scale) {
  return worley_frequency / clamp(turret_scale, CG_TURRET_SCALE_MIN, CG_TURRET_SCALE_MAX);
}

/* Offset of the turret lattice (x, y at frequency ft, z at ft x CG_TURRET_ASPECT). */
CG_FN CG_VEC3 cg_turret_offset(CG_VEC3 location, float stationary, CG_VEC3 wind_direction, float wind_strength,
                               float time, float ft) {
  CG_VEC3 a = cg_noise_offset(location, stationary, wind_direction, wind_strength, time, ft);
  CG_VEC3 b = cg_noise_offset(location, stationary, wind_direction, wind_strength, time, ft * CG_TURRET_ASPECT);
  return CG_VEC3(a[0], a[1], b[2]);
}

/* A (warped) point in turret lattice units: cells CG_TURRET_ASPECT^-1 times taller than wide. */
CG_FN CG_VEC3 cg_turret_point(CG_VEC3 q, float ft, CG_VEC3 offset) {
  return CG_VEC3(q[0] * ft + offset[0], q[1] * ft + offset[1], q[2] * (ft * CG_TURRET_ASPECT) + offset[2]);
}

/* The turret term: one Worley billow octave in [0, 1] (small near a turret's centre). */
CG_FN float cg_turret(CG_VEC3 pt, int seed) {
  return smoothstep(0, 1, cg_worley_f1(pt[0], pt[1], pt[2], seed ^ CG_SEED_SALT_TURRET));
}

/* N with the turrets mixed in (weight ti in [0, 1]): still in [0, 1]. */
CG_FN float cg_turret_mix(float n, float turret, float ti) { return clamp(mix(n, turret, ti), 0, 1); }

/* Cloud Noise (thesis 3.3): the distortion texture N in [0, 1], neutral 1/2.
 *   P  = gradient-noise fBm in [-1,1] (Noise Detail octaves, gain Noise Whisp)
 *   W  = Worley-billow fBm in [0,1] (2 octaves, gain Worley Clump)
 *   Sw = 1/2 + 1/2 sin(2 pi (f_wave x_w + warp P))          (sine texture)
 *   Pf = mix(P, 2 min(|P| s, 1) - 1, Fibres)                 (fibres, s = CG_FIBRE_SHARPNESS)
 *   N0 = clamp(mix(1/2, mix(W, Sw, Wave), Worley Influence)
 *              * mix(1, 1 + 2 contrast Pf, Noise Influence), 0, 1)   (Perlin–Worley)
 *   N  = clamp(mix(N0, W_T, Turret Influence), 0, 1)    (W_T: one large Worley octave)
 * pw, pp and pt are the (warped) point in Worley, gradient-noise and turret lattice units. */
CG_FN float cg_cloud_noise(CG_VEC3 pw, CG_VEC3 pp, CG_VEC3 pt, float w4, float worley_influence, float worley_clump,
                           float wave, float noise_influence, float noise_detail, float noise_whisp, float fibres,
                           float turret_influence, float lod_worley_octaves, float lod_perlin_octaves, int seed) {
  float wi = clamp(worley_influence, 0, 1);
  float wv = clamp(wave, 0, 1);
  float ni = clamp(noise_influence, 0, 1);
  float ti = clamp(turret_influence, 0, 1);
  float p = 0;
  if (cg_noise_uses_perlin(wi, wv, ni)) p = cg_perlin_fbm(pp, w4, noise_detail, lod_perlin_octaves, noise_whisp, seed);
  float worley = CG_FLOAT(0.5);
  if (cg_noise_uses_worley(wi, wv))
    worley = cg_worley_fbm(pw, CG_WORLEY_OCTAVES, lod_worley_octaves, worley_clump, seed ^ CG_SEED_SALT_WORLEY);
  float sine = CG_FLOAT(0.5);
  if (cg_noise_uses_sine(wi, wv)) sine = cg_wave_sine(pw[0], p);
  float n = cg_cloud_noise_combine(p, worley, sine, wi, wv, ni, fibres);
  if (ti > 0) n = cg_turret_mix(n, cg_turret(pt, seed), ti);
  return n;
}

CG_NAMESPACE_END

#endif /* CLOUDGEN_SHARED_CLOUD_MODEL_H */
