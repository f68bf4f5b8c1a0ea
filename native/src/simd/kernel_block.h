// simd/kernel_block.h — the batched density kernel, compiled once per instruction set.
//
// Included by exactly one .cpp per level (kernel_baseline.cpp, ...), each
// built with its own -march and defining CG_SIMD_NS. CG_FN is `static inline`
// here, so every shared function this file compiles has internal linkage and
// the linker cannot hand AVX-512 code to a baseline caller (a test checks the
// object files' symbols).
//
// The algorithm mirrors cg::density (model.h) and cg_cloud_noise / cg_fbm
// (shared/) exactly, reordered: per chunk of points, the shape decides which
// points need noise (the others are 0, no noise evaluated), those are
// compacted, and each noise octave is evaluated lanes-across-points by a loop
// the compiler vectorises (`#pragma omp simd`, -fopenmp-simd). The octave
// bookkeeping (weights, amplitudes, LOD) is uniform over a call and stays
// scalar. Same operations in the same order, no FMA contraction
// (-ffp-contract=off), no value-changing flags: equal to the scalar kernel bit
// for bit (tests/native/test_simd.cpp).
#ifndef CG_SIMD_NS
#error "define CG_SIMD_NS (the level's namespace) before including kernel_block.h"
#endif

#define CG_FN static inline
#include "cloudgen/model.h"
#include "levels.h"

namespace cg::CG_SIMD_NS {

namespace {

constexpr int kChunk = 128;  // points per chunk (a multiple of the widest vector, 16 floats)
constexpr int kPad = 16;     // noise loops run over a multiple of this many lanes

// ---- Worley octave through a table of feature points -----------------------------------------------
// cg_worley_f1 hashes the 27 cells around every point (81 cg_mix32 per point and octave). The points of
// a tile or a row usually lie in 1-3 cells per axis at the Worley frequencies, so when the lanes' cells
// span at most kSpan cells per axis, the feature points of those cells and their neighbours are hashed
// once into a table and each lane reads its 27. The distances are the same expressions on the same
// values, in the same order: bit for bit cg_worley_f1.
constexpr int kSpan = 3;          // widest cell range per axis the table serves
constexpr int kSide = kSpan + 2;  // ... plus one neighbour on each side
constexpr int kCells = kSide * kSide * kSide;

struct WorleyTable {
  float fx[kCells], fy[kCells], fz[kCells];
};

// The octave's lattice coordinates (as cg_worley_f1 computes them) of n lanes: the cell (before
// masking) and the offset inside it.
struct WorleyCells {
  int cx[kChunk], cy[kChunk], cz[kChunk];
  float dx[kChunk], dy[kChunk], dz[kChunk];
};

// The 27-cell search of cg_worley_f1_full for n lanes whose own cell is table entry base(q).
template <class Base>
[[gnu::always_inline]] inline void worley_lanes(int n, const WorleyTable& T, const WorleyCells& C, const int* offset,
                                                Base base, float* out) {
#pragma omp simd
  for (int q = 0; q < n; ++q) {
    const int b = base(q);
    float best = 16;
    for (int k = -1; k <= 1; k += 1)
      for (int j = -1; j <= 1; j += 1)
        for (int i = -1; i <= 1; i += 1) {
          const int t = b + offset[((k + 1) * 3 + (j + 1)) * 3 + (i + 1)];
          const float ox = i + T.fx[t] - C.dx[q];
          const float oy = j + T.fy[t] - C.dy[q];
          const float oz = k + T.fz[t] - C.dz[q];
          best = min(best, ox * ox + oy * oy + oz * oz);
        }
    out[q] = smoothstep(0, 1, min(sqrt(best), CG_WORLEY_F1_CAP));
  }
}

// smoothstep(0, 1, cg_worley_f1(...)) of n lanes at lattice points (x, y, z) * freq + s with octave seed
// `seed` — the Worley term of cg_fbm_sample — into `out`. False (nothing written) when the cells span
// too much for the table.
bool worley_octave_table(int n, const float* x, const float* y, const float* z, float freq, float s, int seed,
                         WorleyCells& C, float* out) {
  int lo[3] = {1 << 30, 1 << 30, 1 << 30}, hi[3] = {-(1 << 30), -(1 << 30), -(1 << 30)};
  for (int i = 0; i < n; ++i) {
    const float wx = cg_wrap(x[i] * freq + s), wy = cg_wrap(y[i] * freq + s), wz = cg_wrap(z[i] * freq + s);
    const float fx = floor(wx), fy = floor(wy), fz = floor(wz);
    C.cx[i] = int(fx);
    C.cy[i] = int(fy);
    C.cz[i] = int(fz);
    C.dx[i] = wx - fx;
    C.dy[i] = wy - fy;
    C.dz[i] = wz - fz;
  }
  for (int i = 0; i < n; ++i) {
    lo[0] = C.cx[i] < lo[0] ? C.cx[i] : lo[0];
    hi[0] = C.cx[i] > hi[0] ? C.cx[i] : hi[0];
    lo[1] = C.cy[i] < lo[1] ? C.cy[i] : lo[1];
    hi[1] = C.cy[i] > hi[1] ? C.cy[i] : hi[1];
    lo[2] = C.cz[i] < lo[2] ? C.cz[i] : lo[2];
    hi[2] = C.cz[i] > hi[2] ? C.cz[i] : hi[2];
  }
  for (int a = 0; a < 3; ++a)
    if (hi[a] - lo[a] >= kSpan) return false;
  // Feature points of cells lo - 1 .. hi + 1 (the hash chain of cg_worley_f1: z, then y, then x): as
  // many cells as the lanes need, so a chunk inside one cell hashes the 27 cells of one point.
  const int sx = hi[0] - lo[0] + 3, sy = hi[1] - lo[1] + 3, sz = hi[2] - lo[2] + 3;
  // x-major (entry a * rows + c * sy + b for cell (a, b, c)), so the x hashes run along all rows at once
  const int rows = sz * sy;
  int hy[kSide * kSide];
  for (int c = 0; c < sz; ++c) {
    const int hz = cg_mix32(((lo[2] - 1 + c) & CG_PERIOD_MASK) ^ seed);
    for (int b = 0; b < sy; ++b) hy[c * sy + b] = cg_mix32(((lo[1] - 1 + b) & CG_PERIOD_MASK) ^ hz);
  }
  WorleyTable T;
  for (int a = 0; a < sx; ++a) {
    const int ix = (lo[0] - 1 + a) & CG_PERIOD_MASK;
    float *fx = T.fx + a * rows, *fy = T.fy + a * rows, *fz = T.fz + a * rows;
#pragma omp simd
    for (int r = 0; r < rows; ++r) {
      const int h = cg_mix32(ix ^ hy[r]);
      fx[r] = cg_feature(h);
      fy[r] = cg_feature(cg_mix32(h ^ CG_WORLEY_SALT_Y));
      fz[r] = cg_feature(cg_mix32(h ^ CG_WORLEY_SALT_Z));
    }
  }
  int offset[27];  // table offset of neighbour (i, j, k), in cg_worley_f1's order
  for (int k = -1, c = 0; k <= 1; k += 1)
    for (int j = -1; j <= 1; j += 1)
      for (int i = -1; i <= 1; i += 1) offset[c++] = i * rows + k * sy + j;
  if (sx == 3 && sy == 3 && sz == 3)  // every lane in one cell: the table reads are uniform, no gathers
    worley_lanes(n, T, C, offset, [](int) { return 1 * 9 + 1 * 3 + 1; }, out);
  else
    worley_lanes(
        n, T, C, offset,
        [&](int q) { return (C.cx[q] - lo[0] + 1) * rows + (C.cz[q] - lo[2] + 1) * sy + (C.cy[q] - lo[1] + 1); }, out);
  return true;
}

// ---- Gradient-noise octave through a table of corner gradients ----------------------------------------
// cg_perlin4 hashes the 16 corners of every point's 4D lattice cell (30 cg_mix32 per point and octave).
// The 4th coordinate is uniform over a call (its 2 lattice values are shared), and at the low octaves
// the points of a tile or a row lie in a few cells per axis: then the gradient index (hash & 31) of
// every corner of those cells is hashed once into a table (the hash chain of cg_perlin4: w, then z,
// y, x) and each lane reads its 16. The gradients, interpolations and clamp are cg_perlin4's
// expressions on the same values in the same order: bit for bit cg_perlin4.
constexpr int kGradMaxCorners = 512;  // largest table (corners per w value) the kernel builds

// The table, x-major so that its loops run along the long axis (rows: w value v, z, y) and vectorise.
struct GradTable {
  int hy[2 * kGradMaxCorners];        // hash of row r = (v * sz + z) * sy + y (the chain w, z, y)
  int j[2 * kGradMaxCorners + 1];     // gradient index of corner x of row r: j[x * rows + r]
  int pack[2 * kGradMaxCorners + 1];  // j[t], j[t + rows], j[t + 1], j[t + rows + 1], 5 bits each: the 4
                                      // corners (x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1) of a face
};

// v * -1 when `sign` is the sign bit, v * 1 when it is 0: a float product by -1 or 1 is exact (the sign
// bit flipped, or v), so this is bit for bit the product.
[[gnu::always_inline]] inline float flip_sign(float v, int sign) {
  return __builtin_bit_cast(float, __builtin_bit_cast(int, v) ^ sign);
}

// cg_grad4 with its arithmetic selections as selects and its products by -1 or 1 as sign flips. cg_grad4's x * (1 - s)
// + y * s (s 0 or 1) is exactly x or y unless the one chosen is -0 (-0 * 1 + 0 * y = +0 for y >= 0): its arguments here
// are the lane's offsets in its cell, d = u - floor(u) >= +0 and d - 1 with d <= 1, differences of floats, which are
// never -0 (a difference is -0 only as -0 - +0, and floor(u) = +0 means u >= +0); and all finite. The signed sum is
// cg_grad4's, same products, same order: the value is bit for bit cg_grad4's.
[[gnu::always_inline]] inline float grad_select(int h, float x, float y, float z, float w) {
  const int j = h & 31;
  const float a = j >= 24 ? y : x;
  const float b = j >= 16 ? z : y;
  const float c = j >= 8 ? w : z;
  return flip_sign(a, (j & 1) << 31) + flip_sign(b, (j & 2) << 30) + flip_sign(c, (j & 4) << 29);
}

// Interpolation along x of one lattice edge whose corners have gradient indices j0, j1 (cg_perlin4_x).
[[gnu::always_inline]] inline float grad_edge(int j0, int j1, float dx, float dy, float dz, float dw, float ux) {
  return mix(grad_select(j0, dx, dy, dz, dw), grad_select(j1, dx - 1, dy, dz, dw), ux);
}

// Gradient index of corner c (x end + 2 * y end) of a cell's (w, z) face, packed as GradTable::pack.
[[gnu::always_inline]] inline int corner(int pack, int c) { return (pack >> (5 * c)) & 31; }

// The 8 corners of one w value of a cell whose z faces are packed in p0, p1 (cg_perlin4_xyz).
[[gnu::always_inline]] inline float grad_cube(int p0, int p1, float dx, float dy, float dz, float dw, float ux,
                                              float uy, float uz) {
  const float a = mix(grad_edge(corner(p0, 0), corner(p0, 1), dx, dy, dz, dw, ux),
                      grad_edge(corner(p0, 2), corner(p0, 3), dx, dy - 1, dz, dw, ux), uy);
  const float c = mix(grad_edge(corner(p1, 0), corner(p1, 1), dx, dy, dz - 1, dw, ux),
                      grad_edge(corner(p1, 2), corner(p1, 3), dx, dy - 1, dz - 1, dw, ux), uy);
  return mix(a, c, uz);
}

// cg_perlin4's interpolations and clamp for n lanes whose cell's (w0, z0) face is GradTable::pack entry
// face(q); its z1 face is oz further, its w1 faces ow further (4 gathers per lane instead of 16).
template <class Face>
[[gnu::always_inline]] inline void gradient_lanes(int n, const int* P, int oz, int ow, float dw, float uw,
                                                  const WorleyCells& C, Face face, float* out) {
  const float dw1 = dw - 1;
#pragma omp simd
  for (int q = 0; q < n; ++q) {
    const int b = face(q);
    const float dx = C.dx[q], dy = C.dy[q], dz = C.dz[q];
    const float ux = cg_fade(dx), uy = cg_fade(dy), uz = cg_fade(dz);
    const float n0 = grad_cube(P[b], P[b + oz], dx, dy, dz, dw, ux, uy, uz);
    const float n1 = grad_cube(P[b + ow], P[b + ow + oz], dx, dy, dz, dw1, ux, uy, uz);
    out[q] = clamp(mix(n0, n1, uw) * CG_PERLIN_NORM, -1, 1);
  }
}

// cg_perlin4(x * freq + s, y * freq + s, z * freq + s, w + s, seed) of n lanes — the gradient term of
// cg_fbm_sample — into `out`. False (nothing written) when the cells span too much for the table to pay.
bool gradient_octave_table(int n, const float* x, const float* y, const float* z, float w, float freq, float s,
                           int seed, WorleyCells& C, GradTable& T, float* out) {
  for (int i = 0; i < n; ++i) {
    const float wx = cg_wrap(x[i] * freq + s), wy = cg_wrap(y[i] * freq + s), wz = cg_wrap(z[i] * freq + s);
    const float fx = floor(wx), fy = floor(wy), fz = floor(wz);
    C.cx[i] = int(fx);
    C.cy[i] = int(fy);
    C.cz[i] = int(fz);
    C.dx[i] = wx - fx;
    C.dy[i] = wy - fy;
    C.dz[i] = wz - fz;
  }
  int lo[3] = {1 << 30, 1 << 30, 1 << 30}, hi[3] = {-(1 << 30), -(1 << 30), -(1 << 30)};
  for (int i = 0; i < n; ++i) {
    lo[0] = C.cx[i] < lo[0] ? C.cx[i] : lo[0];
    hi[0] = C.cx[i] > hi[0] ? C.cx[i] : hi[0];
    lo[1] = C.cy[i] < lo[1] ? C.cy[i] : lo[1];
    hi[1] = C.cy[i] > hi[1] ? C.cy[i] : hi[1];
    lo[2] = C.cz[i] < lo[2] ? C.cz[i] : lo[2];
    hi[2] = C.cz[i] > hi[2] ? C.cz[i] : hi[2];
  }
  // corners lo .. hi + 1 per axis; the table pays when it hashes well under the lanes' 16 corners each
  const long sx = long(hi[0]) - lo[0] + 2, sy = long(hi[1]) - lo[1] + 2, sz = long(hi[2]) - lo[2] + 2;
  if (sx > kGradMaxCorners || sy > kGradMaxCorners || sz > kGradMaxCorners) return false;
  const long corners = sx * sy * sz;
  if (corners > kGradMaxCorners || corners > 4L * n) return false;
  // cg_perlin4's 4th coordinate, uniform over the lanes
  const float ww = cg_wrap(w + s);
  const float fw = floor(ww);
  const int iw0 = int(fw) & CG_PERIOD_MASK;
  const int iw1 = (iw0 + 1) & CG_PERIOD_MASK;
  const float dw = ww - fw;
  const float uw = cg_fade(dw);
  const int hw[2] = {cg_mix32(iw0 ^ seed), cg_mix32(iw1 ^ seed)};
  // the hash chain of cg_perlin4 (w, then z, y, x), rows first, then each x along all rows
  const int nz = int(sz), ny = int(sy), nx = int(sx), rows = 2 * nz * ny;
  for (int v = 0; v < 2; ++v)
    for (int c = 0; c < nz; ++c) {
      const int hz = cg_mix32(((lo[2] + c) & CG_PERIOD_MASK) ^ hw[v]);
      int* hy = T.hy + (v * nz + c) * ny;
#pragma omp simd
      for (int b = 0; b < ny; ++b) hy[b] = cg_mix32(((lo[1] + b) & CG_PERIOD_MASK) ^ hz);
    }
  for (int a = 0; a < nx; ++a) {
    const int ix = (lo[0] + a) & CG_PERIOD_MASK;
    int* J = T.j + a * rows;
#pragma omp simd
    for (int r = 0; r < rows; ++r) J[r] = cg_mix32(ix ^ T.hy[r]) & 31;
  }
  // each face's 4 corners packed (entries whose y + 1 or x + 1 runs past the table are never read)
  T.j[nx * rows] = 0;
  const int faces = (nx - 1) * rows;
  const int* J = T.j;
#pragma omp simd
  for (int t = 0; t < faces; ++t) T.pack[t] = J[t] | J[t + rows] << 5 | J[t + 1] << 10 | J[t + rows + 1] << 15;
  const int oz = ny, ow = nz * ny;
  if (corners == 8)  // every lane in one cell: the table reads are uniform, no gathers
    gradient_lanes(n, T.pack, oz, ow, dw, uw, C, [](int) { return 0; }, out);
  else
    gradient_lanes(
        n, T.pack, oz, ow, dw, uw, C,
        [&](int q) { return (C.cx[q] - lo[0]) * rows + (C.cz[q] - lo[2]) * ny + (C.cy[q] - lo[1]); }, out);
  return true;
}

struct Scratch {
  WorleyCells cells;
  GradTable grad;
  float sample[kChunk];
};

struct alignas(64) Lanes {
  float x[kChunk], y[kChunk], z[kChunk];  // the point, local frame
  float a[kChunk], b[kChunk], c[kChunk];  // the point in one noise's lattice units
  float shape[kChunk], distortion[kChunk], edge[kChunk], perlin[kChunk], worley[kChunk], sine[kChunk], turret[kChunk],
      sum[kChunk];
  int index[kChunk];  // position of lane i in the caller's arrays
  Scratch scratch;
};

// cg_fbm over n lanes at points (x, y, z) and 4th coordinate w: the same
// bookkeeping, the octave loop outside, the lanes inside.
void fbm_lanes(int kind, int n, const float* x, const float* y, const float* z, float w, float octaves,
               float lod_octaves, float gain, int seed, float* sum, float* result, Scratch& scratch) {
  const float n_decl = clamp(octaves, 0, CG_MAX_OCTAVES);
  const float n_eval = min(n_decl, lod_octaves);
  const float g = clamp(gain, 0, CG_MAX_GAIN);
  const float mean = kind == CG_FBM_WORLEY ? 0.5f : 0.0f;
  for (int i = 0; i < n; ++i) sum[i] = 0.0f;
  float norm = 0.0f, amp = 1.0f, freq = 1.0f;
  // once the lanes span too many cells for a table, the finer octaves nearly always do too: stop trying (either path
  // gives the same bits; this only saves the attempt on scattered points)
  bool table = true;
  for (int k = 0; k < CG_MAX_OCTAVES; k += 1) {
    const float wd = cg_octave_weight(n_decl, k);
    if (wd <= 0.0f) break;
    norm += amp * wd;
    const float we = cg_octave_weight(n_eval, k);
    const float aw = amp * wd;
    if (we > 0.0f) {
      const float t = we / wd;
      if (kind == CG_FBM_WORLEY) {
        // cg_fbm_sample's Worley branch: shift s, octave seed, then the table when the cells allow it
        if (table && (table = worley_octave_table(n, x, y, z, freq, k * CG_OCTAVE_SHIFT, cg_mix32(seed ^ k),
                                                  scratch.cells, scratch.sample))) {
#pragma omp simd
          for (int i = 0; i < n; ++i) sum[i] += aw * mix(mean, scratch.sample[i], t);
        } else {
#pragma omp simd
          for (int i = 0; i < n; ++i)
            sum[i] += aw * mix(mean, cg_fbm_sample(CG_FBM_WORLEY, vec3(x[i], y[i], z[i]), w, freq, k, seed), t);
        }
      } else if (table && (table = gradient_octave_table(n, x, y, z, w, freq, k * CG_OCTAVE_SHIFT, cg_mix32(seed ^ k),
                                                         scratch.cells, scratch.grad, scratch.sample))) {
        // cg_fbm_sample's gradient branch through the corner table
#pragma omp simd
        for (int i = 0; i < n; ++i) sum[i] += aw * mix(mean, scratch.sample[i], t);
      } else {
#pragma omp simd
        for (int i = 0; i < n; ++i)
          sum[i] += aw * mix(mean, cg_fbm_sample(CG_FBM_GRADIENT, vec3(x[i], y[i], z[i]), w, freq, k, seed), t);
      }
    } else {
      for (int i = 0; i < n; ++i) sum[i] += aw * mean;
    }
    amp *= g;
    freq *= 2.0f;
  }
  for (int i = 0; i < n; ++i) result[i] = norm > 0.0f ? sum[i] / norm : mean;
}

// Lattice coordinates p * frequency + offset of n lanes (as noise_at computes them).
void to_lattice(Lanes& L, int n, float frequency, vec3 offset) {
#pragma omp simd
  for (int i = 0; i < n; ++i) {
    L.a[i] = L.x[i] * frequency + offset[0];
    L.b[i] = L.y[i] * frequency + offset[1];
    L.c[i] = L.z[i] * frequency + offset[2];
  }
}

// Shape stage: out = 0 where the point is outside the box or provably empty;
// the others are appended to L (point, shape, index). Returns their count.
int shape_stage(const Model& m, const vec3* points, int count, std::size_t first, float* out, Lanes& L) {
  int n = 0;
  for (int q = 0; q < count; ++q) {
    const vec3 p = points[q];
    const vec3 g(p[0] / m.box[0] + 0.5f, p[1] / m.box[1] + 0.5f, p[2] / m.box[2] + 0.5f);
    out[q] = 0.0f;
    if (!(g[0] >= 0.0f && g[0] <= 1.0f && g[1] >= 0.0f && g[1] <= 1.0f && g[2] >= 0.0f && g[2] <= 1.0f)) continue;
    const float curve_value =
        m.shape_mode == 1 ? cg_curve_eval(m.curve, cg_shape_height(g[2], m.cloud_scale, m.base_height, m.top_height))
                          : 0.0f;
    const float s = cg_shape(g, m.cloud_scale, m.shape_mode, m.shape_exponent, curve_value, m.base_height, m.top_height,
                             m.lean, m.sheet, m.anvil, m.anvil_height);
    if (cg_shape_proves_empty(s, m.distortion)) continue;
    L.x[n] = p[0];
    L.y[n] = p[1];
    L.z[n] = p[2];
    L.shape[n] = fibred_shape_at_generated(m, g, s);
    L.distortion[n] = distortion_at_generated(m, g);
    L.edge[n] = edge_width_at_generated(m, g);
    L.index[n] = int(first) + q;
    ++n;
  }
  return n;
}

// Noise and eq. 3.4 for the n lanes of L (padded to a multiple of kPad), written to out.
void noise_stage(const Model& m, const Lod& lod, Lanes& L, int n, float* out) {
  const int padded = (n + kPad - 1) / kPad * kPad;
  for (int i = n; i < padded; ++i) {  // padding lanes repeat the last point; their values are dropped
    L.x[i] = L.x[n - 1];
    L.y[i] = L.y[n - 1];
    L.z[i] = L.z[n - 1];
  }
  // warped + cg_noise_warp: the point the noise is read at (the lanes' x, y, z are not needed after this)
  for (int i = 0; i < padded; ++i) {
    const vec3 q = cg_noise_warp(warped(m, vec3(L.x[i], L.y[i], L.z[i])), m.stretch, m.shear);
    L.x[i] = q[0];
    L.y[i] = q[1];
    L.z[i] = q[2];
  }
  const float wi = clamp(m.worley_influence, 0, 1);
  const float wv = clamp(m.wave, 0, 1);
  const float ni = clamp(m.noise_influence, 0, 1);
  const float ti = clamp(m.turret_influence, 0, 1);
  for (int i = 0; i < padded; ++i) L.perlin[i] = 0.0f;
  if (cg_noise_uses_perlin(wi, wv, ni)) {
    to_lattice(L, padded, m.perlin_frequency, m.perlin_offset);
    fbm_lanes(CG_FBM_GRADIENT, padded, L.a, L.b, L.c, m.w4, m.noise_detail, lod.perlin_octaves, m.noise_whisp, m.seed,
              L.sum, L.perlin, L.scratch);
  }
  to_lattice(L, padded, m.worley_frequency, m.worley_offset);
  for (int i = 0; i < padded; ++i) L.worley[i] = 0.5f;
  if (cg_noise_uses_worley(wi, wv))
    fbm_lanes(CG_FBM_WORLEY, padded, L.a, L.b, L.c, 0.0f, CG_WORLEY_OCTAVES, lod.worley_octaves, m.worley_clump,
              m.seed ^ CG_SEED_SALT_WORLEY, L.sum, L.worley, L.scratch);
  for (int i = 0; i < padded; ++i) L.sine[i] = 0.5f;
  if (cg_noise_uses_sine(wi, wv))
    for (int i = 0; i < n; ++i) L.sine[i] = cg_wave_sine(L.a[i], L.perlin[i]);
  if (ti > 0.0f) {
    // cg_turret: one Worley octave on the turret lattice, through the table when the cells allow it
    for (int i = 0; i < padded; ++i) {
      const vec3 t = cg_turret_point(vec3(L.x[i], L.y[i], L.z[i]), m.turret_frequency, m.turret_offset);
      L.a[i] = t[0];
      L.b[i] = t[1];
      L.c[i] = t[2];
    }
    const int tseed = m.seed ^ CG_SEED_SALT_TURRET;
    if (!worley_octave_table(padded, L.a, L.b, L.c, 1.0f, 0.0f, tseed, L.scratch.cells, L.turret))
      for (int i = 0; i < padded; ++i) L.turret[i] = cg_turret(vec3(L.a[i], L.b[i], L.c[i]), m.seed);
  }
#pragma omp simd
  for (int i = 0; i < padded; ++i) {
    float noise = cg_cloud_noise_combine(L.perlin[i], L.worley[i], L.sine[i], wi, wv, ni, m.fibres);
    if (ti > 0.0f) noise = cg_turret_mix(noise, L.turret[i], ti);
    L.sum[i] = cg_cloud_main(L.shape[i], noise, L.distortion[i], m.density, L.edge[i]);
  }
  for (int i = 0; i < n; ++i) out[L.index[i]] = L.sum[i];
}

}  // namespace

void density_points(const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out) {
  Lanes L;
  for (std::size_t first = 0; first < n; first += kChunk) {
    const int count = int(n - first < std::size_t(kChunk) ? n - first : std::size_t(kChunk));
    const int kept = shape_stage(m, points + first, count, 0, out + first, L);
    if (kept > 0) noise_stage(m, lod, L, kept, out + first);
  }
}

}  // namespace cg::CG_SIMD_NS
