/* cloudgen/shared/noise.h — hash, 4D gradient noise, Worley F1 and their fBm.
 *
 * Shared by C++ and OSL (see lang.h for the rules). Every function here is
 * pure and bounded; docs/model.md gives the formulas and the proofs of the
 * bounds. All lattices have period CG_PERIOD in every axis, so any offset may
 * be reduced modulo CG_PERIOD before it meets a small local coordinate; that
 * is what keeps the noise exact far from the origin.
 */
#ifndef CLOUDGEN_SHARED_NOISE_H
#define CLOUDGEN_SHARED_NOISE_H

#include "lang.h"

CG_NAMESPACE_BEGIN

#define CG_PERIOD 256 /* lattice period of every noise, in lattice cells */
#define CG_PERIOD_MASK 255
#define CG_MAX_OCTAVES 16              /* hard cap on fBm octaves (also the kernel's clamp) */
#define CG_MAX_GAIN 8                  /* kernel clamp of fBm gain */
#define CG_WORLEY_JITTER CG_FLOAT(0.9) /* feature point stays in the middle 90 % of its cell */
/* 1/1.25: just above the largest |raw 4D gradient noise| seen in 2e6 random samples (1.13);
 * the result is clamped to [-1, 1] so the bound holds by construction. */
#define CG_PERLIN_NORM CG_FLOAT(0.8)
/* per-octave shift so that lattice points of successive octaves do not line up */
#define CG_OCTAVE_SHIFT CG_FLOAT(0.3183099)

/* lowbias32 finalizer (C. Wellons): a full-avalanche 32-bit integer mix. */
CG_FN int cg_mix32(int v) {
  int x = v;
  x = x ^ cg_shr(x, 16);
  x = cg_imul(x, 2146121005); /* 0x7feb352d */
  x = x ^ cg_shr(x, 15);
  x = cg_imul(x, -2073254261); /* 0x846ca68b as a signed 32-bit int */
  x = x ^ cg_shr(x, 16);
  return x;
}

/* 24 low bits of a hash as a float in [0, 1): exact in both languages. */
CG_FN float cg_hash_unit(int h) { return float(h & 16777215) / 16777216; }

/* x reduced to [-CG_PERIOD/2, CG_PERIOD/2]: the lattice is periodic, so the
 * noise value is unchanged, the integer cell index can never overflow, and the
 * float keeps the same precision on both sides of 0. */
CG_FN float cg_wrap(float x) { return x - CG_PERIOD * floor(x / CG_PERIOD + CG_FLOAT(0.5)); }

CG_FN float cg_fade(float t) { return t * t * t * (t * (t * 6 - 15) + 10); }

/* Dot product of one of 32 gradients (the permutations of (±1,±1,±1,0)) with d.
 * The selections and signs are arithmetic, not `?:`: as data-dependent
 * branches they were mispredicted ~200 times per cloud sample (bench/), and
 * x * 1 + y * 0 selects exactly, so the values are the same as with branches. */
CG_FN float cg_grad4(int h, float x, float y, float z, float w) {
  int j = h & 31;
  float sa = float(j >= 24);
  float sb = float(j >= 16);
  float sc = float(j >= 8);
  float a = x * (1 - sa) + y * sa;
  float b = y * (1 - sb) + z * sb;
  float c = z * (1 - sc) + w * sc;
  return a * (1 - 2 * (j & 1)) + b * (1 - (j & 2)) + c * (1 - ((j & 4) >> 1));
}

/* Interpolation along x between the two corners of one lattice edge. */
CG_FN float cg_perlin4_x(int hy, int ix0, int ix1, float dx, float dy, float dz, float dw, float ux) {
  float g0 = cg_grad4(cg_mix32(ix0 ^ hy), dx, dy, dz, dw);
  float g1 = cg_grad4(cg_mix32(ix1 ^ hy), dx - 1, dy, dz, dw);
  return mix(g0, g1, ux);
}

CG_FN float cg_perlin4_xy(int hz, int ix0, int ix1, int iy0, int iy1, float dx, float dy, float dz, float dw, float ux,
                          float uy) {
  float a = cg_perlin4_x(cg_mix32(iy0 ^ hz), ix0, ix1, dx, dy, dz, dw, ux);
  float b = cg_perlin4_x(cg_mix32(iy1 ^ hz), ix0, ix1, dx, dy - 1, dz, dw, ux);
  return mix(a, b, uy);
}

CG_FN float cg_perlin4_xyz(int hw, int ix0, int ix1, int iy0, int iy1, int iz0, int iz1, float dx, float dy, float dz,
                           float dw, float ux, float uy, float uz) {
  float a = cg_perlin4_xy(cg_mix32(iz0 ^ hw), ix0, ix1, iy0, iy1, dx, dy, dz, dw, ux, uy);
  float b = cg_perlin4_xy(cg_mix32(iz1 ^ hw), ix0, ix1, iy0, iy1, dx, dy, dz - 1, dw, ux, uy);
  return mix(a, b, uz);
}

/* 4D gradient (Perlin) noise, quintic fade, integer hash; result in [-1, 1]. */
CG_FN float cg_perlin4(float px, float py, float pz, float pw, int seed) {
  float x = cg_wrap(px);
  float y = cg_wrap(py);
  float z = cg_wrap(pz);
  float w = cg_wrap(pw);
  float fx = floor(x);
  float fy = floor(y);
  float fz = floor(z);
  float fw = floor(w);
  int ix0 = int(fx) & CG_PERIOD_MASK;
  int iy0 = int(fy) & CG_PERIOD_MASK;
  int iz0 = int(fz) & CG_PERIOD_MASK;
  int iw0 = int(fw) & CG_PERIOD_MASK;
  int ix1 = (ix0 + 1) & CG_PERIOD_MASK;
  int iy1 = (iy0 + 1) & CG_PERIOD_MASK;
  int iz1 = (iz0 + 1) & CG_PERIOD_MASK;
  int iw1 = (iw0 + 1) & CG_PERIOD_MASK;
  float dx = x - fx;
  float dy = y - fy;
  float dz = z - fz;
  float dw = w - fw;
  float ux = cg_fade(dx);
  float uy = cg_fade(dy);
  float uz = cg_fade(dz);
  float uw = cg_fade(dw);
  float n0 = cg_perlin4_xyz(cg_mix32(iw0 ^ seed), ix0, ix1, iy0, iy1, iz0, iz1, dx, dy, dz, dw, ux, uy, uz);
  float n1 = cg_perlin4_xyz(cg_mix32(iw1 ^ seed), ix0, ix1, iy0, iy1, iz0, iz1, dx, dy, dz, dw - 1, ux, uy, uz);
  return clamp(mix(n0, n1, uw) * CG_PERLIN_NORM, -1, 1);
}

/* Feature point coordinate inside its cell, in [0.05, 0.95]. */
CG_FN float cg_feature(int h) { return CG_FLOAT(0.5) + CG_WORLEY_JITTER * (cg_hash_unit(h) - CG_FLOAT(0.5)); }

/* Hash salts of a cell's feature point y and z coordinates (x uses the cell hash itself). */
#define CG_WORLEY_SALT_Y 1013904223
#define CG_WORLEY_SALT_Z 1664525

/* Distance beyond which Worley F1 is capped: a feature point outside the 27
 * cells around p lies at least one cell plus the margin (1 - jitter)/2 away. */
#define CG_WORLEY_F1_CAP (1 + (1 - CG_WORLEY_JITTER) / 2)

#define CG_WORLEY_GAP_MARGIN CG_FLOAT(1.0e-5) /* >> the rounding of a cell offset (|offset| < 2) */

/* A lower bound of |n + f - d| over the feature offsets f a cell can have
 * ([1/2 - jitter/2, 1/2 + jitter/2]), for the neighbour n in {-1, 0, 1} along
 * one axis and p's offset d in its own cell, less a margin that covers every
 * rounding of the offset as cg_worley_f1 computes it: so the computed offset is
 * never below the computed gap. */
CG_FN float cg_worley_gap(int n, float d) {
  float lo = CG_FLOAT(0.5) - CG_WORLEY_JITTER / 2;
  float hi = CG_FLOAT(0.5) + CG_WORLEY_JITTER / 2;
  float g = max(max(lo - d, d - hi), 0);
  if (n < 0) g = 1 - hi + d;
  if (n > 0) g = 1 + lo - d;
  return max(g - CG_WORLEY_GAP_MARGIN, 0);
}

/* Squared distance from p (offset dx, dy, dz in its cell) to the feature point
 * of the neighbour cell (i, j, k) whose x hash is h. */
CG_FN float cg_worley_d2(int h, int i, int j, int k, float dx, float dy, float dz) {
  float ox = i + cg_feature(h) - dx;
  float oy = j + cg_feature(cg_mix32(h ^ CG_WORLEY_SALT_Y)) - dy;
  float oz = k + cg_feature(cg_mix32(h ^ CG_WORLEY_SALT_Z)) - dz;
  return ox * ox + oy * oy + oz * oz;
}

/* The unpruned 27-cell search: what cg_worley_f1 equals bit for bit (tests hold the two
 * equal); with CG_WORLEY_FULL_SEARCH defined, cg_worley_f1 is this (the benchmarks' shader
 * of the thesis's kind: Blender's Voronoi texture searches all 27 cells). */
CG_FN float cg_worley_f1_full(float px, float py, float pz, int seed) {
  float x = cg_wrap(px);
  float y = cg_wrap(py);
  float z = cg_wrap(pz);
  float fx = floor(x);
  float fy = floor(y);
  float fz = floor(z);
  int ix = int(fx) & CG_PERIOD_MASK;
  int iy = int(fy) & CG_PERIOD_MASK;
  int iz = int(fz) & CG_PERIOD_MASK;
  float best = 16;
  for (int k = -1; k <= 1; k += 1) {
    int hz = cg_mix32(((iz + k) & CG_PERIOD_MASK) ^ seed);
    for (int j = -1; j <= 1; j += 1) {
      int hy = cg_mix32(((iy + j) & CG_PERIOD_MASK) ^ hz);
      for (int i = -1; i <= 1; i += 1)
        best = min(best, cg_worley_d2(cg_mix32(((ix + i) & CG_PERIOD_MASK) ^ hy), i, j, k, x - fx, y - fy, z - fz));
    }
  }
  return min(sqrt(best), CG_WORLEY_F1_CAP);
}

/* Worley F1, capped: min(distance to the nearest feature point, 1.05), one
 * point per cell, the 27 cells around p searched. Exact — equal to a search of
 * every cell, then capped — because no point outside the 27 cells can be nearer
 * than the cap (tests compare with a 125-cell search). The cap is invisible in
 * the model: the billow term smoothstep(0, 1, F1) is already 1 from F1 = 1.
 * Result in [0, 1.05]; 1-Lipschitz.
 *
 * Pruned: p's own cell first, then a plane, row or cell of neighbours is
 * skipped (its hashes never computed) when the gap to it — summed in the order
 * the distance is, each gap at most the computed offset — is already no nearer
 * than the best so far. Float + and * are monotone, so a skipped feature point's
 * computed distance is >= that bound >= the best: the minimum, and so the
 * result, is bit for bit that of the full 27-cell search (tests/native check it
 * against one). About 7 of the 27 cells are hashed on average. */
CG_FN float cg_worley_f1(float px, float py, float pz, int seed) {
#ifdef CG_WORLEY_FULL_SEARCH
  return cg_worley_f1_full(px, py, pz, seed);
#endif
  float x = cg_wrap(px);
  float y = cg_wrap(py);
  float z = cg_wrap(pz);
  float fx = floor(x);
  float fy = floor(y);
  float fz = floor(z);
  int ix = int(fx) & CG_PERIOD_MASK;
  int iy = int(fy) & CG_PERIOD_MASK;
  int iz = int(fz) & CG_PERIOD_MASK;
  float dx = x - fx;
  float dy = y - fy;
  float dz = z - fz;
  float best = cg_worley_d2(cg_mix32(ix ^ cg_mix32(iy ^ cg_mix32(iz ^ seed))), 0, 0, 0, dx, dy, dz);
  for (int k = -1; k <= 1; k += 1) {
    float gz = cg_worley_gap(k, dz);
    float gz2 = gz * gz;
    if (gz2 >= best) continue;
    int hz = cg_mix32(((iz + k) & CG_PERIOD_MASK) ^ seed);
    for (int j = -1; j <= 1; j += 1) {
      float gy = cg_worley_gap(j, dy);
      float gy2 = gy * gy;
      if (gy2 + gz2 >= best) continue;
      int hy = cg_mix32(((iy + j) & CG_PERIOD_MASK) ^ hz);
      for (int i = -1; i <= 1; i += 1) {
        if (i == 0 && j == 0 && k == 0) continue;
        float gx = cg_worley_gap(i, dx);
        if ((gx * gx + gy2) + gz2 >= best) continue;
        best = min(best, cg_worley_d2(cg_mix32(((ix + i) & CG_PERIOD_MASK) ^ hy), i, j, k, dx, dy, dz));
      }
    }
  }
  return min(sqrt(best), CG_WORLEY_F1_CAP);
}

/* Weight of octave k when `octaves` (possibly fractional) are asked for: 1 for
 * whole octaves, the fractional part for the last one (a smooth fade), 0 after. */
CG_FN float cg_octave_weight(float octaves, int k) { return clamp(octaves - k, 0, 1); }

#define CG_FBM_GRADIENT 0 /* octave term: 4D gradient noise, in [-1, 1], mean 0 */
#define CG_FBM_WORLEY 1   /* octave term: smoothstep(0, 1, Worley F1), in [0, 1], mean about 1/2 */

/* The term of octave k (frequency freq = 2^k) at p: the batched kernel
 * (native/src/simd/) calls it lane by lane, cg_fbm point by point. */
CG_FN float cg_fbm_sample(int kind, CG_VEC3 p, float w, float freq, int k, int seed) {
  float s = k * CG_OCTAVE_SHIFT;
  int octave_seed = cg_mix32(seed ^ k);
  float sample = 0;
  if (kind == CG_FBM_WORLEY)
    sample = smoothstep(0, 1, cg_worley_f1(p[0] * freq + s, p[1] * freq + s, p[2] * freq + s, octave_seed));
  else
    sample = cg_perlin4(p[0] * freq + s, p[1] * freq + s, p[2] * freq + s, w + s, octave_seed);
  return sample;
}

/* fBm, lacunarity 2: octave k samples the term at 2^k p (+ a per-octave shift,
 * its own seed), weighted gain^k; the sum is normalised by the sum of the
 * weights of the `octaves` asked for (the last one fractional: it fades in),
 * so the result stays in the term's range for every gain and octave count.
 * Octaves beyond `lod_octaves` (finer than the sampling can hold) are not
 * evaluated: the term's mean stands in for them, faded in the same way. */
CG_FN float cg_fbm(int kind, CG_VEC3 p, float w, float octaves, float lod_octaves, float gain, int seed) {
  float n_decl = clamp(octaves, 0, CG_MAX_OCTAVES);
  float n_eval = min(n_decl, lod_octaves);
  float g = clamp(gain, 0, CG_MAX_GAIN);
  float mean = kind == CG_FBM_WORLEY ? CG_FLOAT(0.5) : 0;
  float sum = 0;
  float norm = 0;
  float amp = 1;
  float freq = 1;
  for (int k = 0; k < CG_MAX_OCTAVES; k += 1) {
    float wd = cg_octave_weight(n_decl, k);
    if (wd <= 0) break;
    norm += amp * wd;
    float we = cg_octave_weight(n_eval, k);
    float term = mean;
    if (we > 0) term = mix(mean, cg_fbm_sample(kind, p, w, freq, k, seed), we / wd);
    sum += amp * wd * term;
    amp *= g;
    freq *= 2;
  }
  return norm > 0 ? sum / norm : mean;
}

/* Gradient-noise fBm in [-1, 1] (w: the 4th coordinate, time). */
CG_FN float cg_perlin_fbm(CG_VEC3 p, float w, float octaves, float lod_octaves, float gain, int seed) {
  return cg_fbm(CG_FBM_GRADIENT, p, w, octaves, lod_octaves, gain, seed);
}

/* Worley-billow fBm in [0, 1], small near feature points. */
CG_FN float cg_worley_fbm(CG_VEC3 p, float octaves, float lod_octaves, float gain, int seed) {
  return cg_fbm(CG_FBM_WORLEY, p, 0, octaves, lod_octaves, gain, seed);
}

CG_NAMESPACE_END

#endif /* CLOUDGEN_SHARED_NOISE_H */
