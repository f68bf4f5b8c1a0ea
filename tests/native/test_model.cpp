// test_model.cpp — the cloud model (eq. 3.4, docs/model.md §4) through cg::prepare,
// cg::shape_at, cg::noise_at and cg::density: hand-computed values with the
// noise switched off, the zero level set, linearity in Density, Stationary and wind.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>

#include "cloudgen/model.h"
#include "cloudgen/params.h"
#include "test_util.h"

namespace {

using cg::vec3;
using cgtest::Rng;

static_assert(CG_PROFILE_FALLOFF == 16, "the hand-computed values below assume S falls off as -16 (h - clamp(h))^2");

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Local point of generated coordinates g: p = (g - 1/2) * box.
vec3 local(const cg::Params& p, double gx, double gy, double gz) {
  const vec3 box = p.vector(cg::BOX_SIZE);
  return {float((gx - 0.5) * double(box[0])), float((gy - 0.5) * double(box[1])), float((gz - 0.5) * double(box[2]))};
}

// The shape term written out independently, in double: T = (2G - 1) / cloud_scale,
// h = (T_z + 1) / 2, S = 1 - (2 h^e - 1)^2 or the piecewise-linear curve at clamp(h),
// minus 16 (h - clamp(h))^2; shape = S - T_x^2 - T_y^2.
double reference_shape(const cg::Params& p, double gx, double gy, double gz) {
  const double cs = double(p.get(cg::CLOUD_SCALE));
  const double tx = (2 * gx - 1) / cs, ty = (2 * gy - 1) / cs, tz = (2 * gz - 1) / cs;
  const double h = (tz + 1) / 2, hc = std::clamp(h, 0.0, 1.0);
  double core;
  if (p.get(cg::SHAPE_MODE) >= 0.5f) {
    const double x = hc * 16;
    const int i = std::min(15, int(std::floor(x)));
    core = double(p.get(cg::SHAPE_CURVE, i)) * (1 - (x - i)) + double(p.get(cg::SHAPE_CURVE, i + 1)) * (x - i);
  } else {
    const double u = 2 * std::pow(hc, double(p.get(cg::SHAPE_EXPONENT))) - 1;
    core = 1 - u * u;
  }
  return core - 16 * (h - hc) * (h - hc) - tx * tx - ty * ty;
}

struct Case {
  const char* where;
  double g[3];
  double shape;    // S(T_z) - T_x^2 - T_y^2, by hand
  double density;  // max(shape, 0) * 20 * Density slider (0.5), by hand
};

void check_cases(const cg::Params& params, const Case* cases, int n) {
  // Tolerance: 1e-5 * max(1, |expected|) (about ten float roundings of values <= 4).
  for (bool distortion_zero : {false, true}) {
    cg::Params p = params;
    if (distortion_zero) {
      // The other way to switch the noise off: noise on, distortion 0.
      p.set(cg::WORLEY_INFLUENCE, 0.8f);
      p.set(cg::NOISE_INFLUENCE, 0.6f);
      p.set(cg::DISTORTION, 0.0f);
    } else {
      cgtest::noise_off(p);
    }
    const cg::Model m = cg::prepare(p);
    for (int i = 0; i < n; ++i) {
      const Case& c = cases[i];
      const vec3 x = local(p, c.g[0], c.g[1], c.g[2]);
      const double tol = 1e-5 * std::max(1.0, std::fabs(c.density));
      EXPECT_NEAR(double(cg::shape_at(m, x)), c.shape, 1e-5 * std::max(1.0, std::fabs(c.shape)))
          << c.where << " g=(" << c.g[0] << ", " << c.g[1] << ", " << c.g[2] << ") params " << cgtest::describe(p);
      EXPECT_NEAR(double(cg::density(m, x)), c.density, tol)
          << c.where << " g=(" << c.g[0] << ", " << c.g[1] << ", " << c.g[2] << ") params " << cgtest::describe(p);
      // The reference sees the float parameters (0.8f is not 0.8): 1e-6.
      EXPECT_NEAR(reference_shape(p, c.g[0], c.g[1], c.g[2]), c.shape, 1e-6) << "reference formula, " << c.where;
      if (!distortion_zero) {
        EXPECT_EQ(cg::noise_at(m, x), 0.5f) << "noise off must give N = 1/2";
      }
    }
  }
}

cg::Params exponent_params(float cloud_scale, float exponent) {
  cg::Params p;
  p.set(cg::CLOUD_SCALE, cloud_scale);
  p.set(cg::SHAPE_MODE, 0.0f);
  p.set(cg::SHAPE_EXPONENT, exponent);
  return p;  // box 2 x 2 x 2, Density 0.5 -> x10
}

TEST(Model, HandValuesExponentProfile) {
  // cloud_scale 1, e = 2: T = 2G - 1, h = G_z, S = 1 - (2 G_z^2 - 1)^2.
  //  centre (1/2,1/2,1/2): h^2 = 1/4, u = -1/2, S = 3/4            -> D = 7.5
  //  edge midpoint (1, 1/2, 1): h = 1, S = 0, T_x = 1              -> -1, D = 0
  //  corner (1,1,1): S(1) = 0, -1 - 1                              -> -2
  //  corner (0,0,0): h^2 = 0, u = -1, S = 0                        -> -2
  //  between (3/4, 1/4, 5/8): h^2 = 0.390625, u = -0.21875, u^2 = 0.0478515625,
  //    S = 0.9521484375, minus 0.25 + 0.25                         -> 0.4521484375, D = 4.521484375
  const Case e2[] = {{"centre", {0.5, 0.5, 0.5}, 0.75, 7.5},
                     {"edge midpoint", {1, 0.5, 1}, -1, 0},
                     {"corner +", {1, 1, 1}, -2, 0},
                     {"corner -", {0, 0, 0}, -2, 0},
                     {"in between", {0.75, 0.25, 0.625}, 0.4521484375, 4.521484375}};
  check_cases(exponent_params(1.0f, 2.0f), e2, 5);

  // cloud_scale 0.8, e = 2: T = (2G - 1) / 0.8.
  //  centre: h = 1/2, S = 3/4                                      -> 0.75, D = 7.5
  //  edge midpoint (1, 1/2, 1): T_x = 1.25, h = 1.125 -> S = 0 - 16 * 0.125^2 = -0.25,
  //    minus 1.5625                                                -> -1.8125
  //  corner (1,1,1): -0.25 - 2 * 1.5625                            -> -3.375
  //  between (3/4, 1/4, 5/8): T = (0.625, -0.625, 0.3125), h = 0.65625, h^2 = 0.4306640625,
  //    u = -0.138671875, S = 1 - 0.019229888916015625, minus 2 * 0.390625
  //                                                                -> 0.199520111083984375
  const Case s08[] = {{"centre", {0.5, 0.5, 0.5}, 0.75, 7.5},
                      {"edge midpoint", {1, 0.5, 1}, -1.8125, 0},
                      {"corner", {1, 1, 1}, -3.375, 0},
                      {"in between", {0.75, 0.25, 0.625}, 0.199520111083984375, 1.99520111083984375}};
  check_cases(exponent_params(0.8f, 2.0f), s08, 4);

  // cloud_scale 1, e = 1: a sphere, 1 - |T|^2; non-cubic box (4, 2, 3) must not matter
  // (the shape lives in generated coordinates).
  //  face centre (1/2, 1/2, 1): T_z = 1                            -> 0
  //  (0.6, 0.3, 0.45): T = (0.2, -0.4, -0.1)                       -> 1 - 0.04 - 0.16 - 0.01 = 0.79
  cg::Params sphere = exponent_params(1.0f, 1.0f);
  const float box[3] = {4, 2, 3};
  sphere.set(cg::BOX_SIZE, box, 3);
  const Case e1[] = {{"face centre", {0.5, 0.5, 1}, 0, 0},
                     {"centre", {0.5, 0.5, 0.5}, 1, 10},
                     {"in between", {0.6, 0.3, 0.45}, 0.79, 7.9}};
  check_cases(sphere, e1, 3);
}

TEST(Model, HandValuesCurveProfile) {
  // A curve of our own (samples at h = i/16), cloud_scale 1, so h = G_z:
  //   0, .5, .8, .9, 1, .9, .8, .75, .7, .6, .5, .4, .3, .2, .1, .05, 0
  //  centre: h = 1/2 -> sample 8 = 0.7                             -> D = 7
  //  (1/2, 1/2, 1/4): sample 4 = 1                                 -> D = 10
  //  (3/4, 1/4, 19/32): h = 9.5/16 -> (0.6 + 0.5)/2 = 0.55, minus 0.5 -> 0.05, D = 0.5
  //  edge midpoint (1/2, 1, 0): sample 0 = 0, T_y = 1              -> -1
  //  corner (0, 0, 1): sample 16 = 0                               -> -2
  //  (1/2, 1/2, 3/32): h = 1.5/16 -> (0.5 + 0.8)/2 = 0.65          -> D = 6.5
  const float curve[CG_CURVE_POINTS] = {0,    0.5f, 0.8f, 0.9f, 1,    0.9f, 0.8f,  0.75f, 0.7f,
                                        0.6f, 0.5f, 0.4f, 0.3f, 0.2f, 0.1f, 0.05f, 0};
  cg::Params p;
  p.set(cg::CLOUD_SCALE, 1.0f);
  p.set(cg::SHAPE_MODE, 1.0f);
  p.set(cg::SHAPE_CURVE, curve, CG_CURVE_POINTS);
  const Case cases[] = {{"centre", {0.5, 0.5, 0.5}, 0.7, 7},
                        {"widest", {0.5, 0.5, 0.25}, 1, 10},
                        {"in between", {0.75, 0.25, 19.0 / 32}, 0.05, 0.5},
                        {"edge midpoint", {0.5, 1, 0}, -1, 0},
                        {"corner", {0, 0, 1}, -2, 0},
                        {"near the base", {0.5, 0.5, 3.0 / 32}, 0.65, 6.5}};
  check_cases(p, cases, 6);
}

TEST(Model, ZeroLevelSetEqualsTheShape) {
  // Noise off: density > 0 exactly where S(T_z) - T_x^2 - T_y^2 > 0 (reference in double),
  // on a 41^3 grid of points, except within a band |shape| <= 1e-5 around the surface.
  struct Set {
    int mode;
    float exponent, cloud_scale;
    float box[3];
  };
  const Set sets[] = {{0, 0.6f, 0.85f, {2, 2, 2}}, {0, 0.3f, 1.0f, {4, 3, 2.5f}}, {0, 3.0f, 0.5f, {1, 1, 1}},
                      {0, 1.0f, 0.7f, {3, 1, 2}},  {1, 0.6f, 0.85f, {4, 4, 3}},   {1, 0.6f, 0.4f, {2, 5, 1}}};
  const int n = 41;
  for (const Set& s : sets) {
    cg::Params p;
    cgtest::noise_off(p);
    p.set(cg::SHAPE_MODE, float(s.mode));
    p.set(cg::SHAPE_EXPONENT, s.exponent);
    p.set(cg::CLOUD_SCALE, s.cloud_scale);
    p.set(cg::BOX_SIZE, s.box, 3);
    const cg::Model m = cg::prepare(p);
    int inside = 0, banded = 0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double g[3] = {i / double(n - 1), j / double(n - 1), k / double(n - 1)};
          const double ref = reference_shape(p, g[0], g[1], g[2]);
          if (std::fabs(ref) <= 1e-5) {
            ++banded;
            continue;
          }
          const float d = cg::density(m, local(p, g[0], g[1], g[2]));
          inside += ref > 0;
          ASSERT_EQ(d > 0.0f, ref > 0) << "g=(" << g[0] << ", " << g[1] << ", " << g[2] << ") shape " << ref
                                       << " density " << d << " params " << cgtest::describe(p);
        }
    EXPECT_GT(inside, 100) << "the cloud should fill part of the box: " << cgtest::describe(p);
    EXPECT_LT(banded, 200) << cgtest::describe(p);
  }
}

TEST(Model, DensityIsLinearInTheDensitySlider) {
  // Noise on (defaults): density(p; s) / density(p; 0.5) == s / 0.5, rel. tol 1e-6
  // (one float multiply by 20 s), and zero where the other is zero.
  Rng rng(21);
  cg::Params base;
  const cg::Model m0 = cg::prepare(base);
  int positive = 0;
  for (float s : {0.05f, 0.25f, 1.0f, 7.3f, 10.0f}) {
    cg::Params p = base;
    p.set(cg::DENSITY, s);
    const cg::Model m = cg::prepare(p);
    for (int i = 0; i < 20000; ++i) {
      const vec3 x(rng.uniformf(-1, 1), rng.uniformf(-1, 1), rng.uniformf(-1, 1));
      const double d0 = double(cg::density(m0, x)), d = double(cg::density(m, x));
      if (d0 == 0) {
        ASSERT_EQ(d, 0.0) << "at " << cgtest::str(x) << " density " << s;
        continue;
      }
      ++positive;
      ASSERT_NEAR(d / d0, double(s) / 0.5, 1e-6 * double(s) / 0.5) << "at " << cgtest::str(x) << " density " << s;
    }
  }
  EXPECT_GT(positive, 10000);
}

TEST(Model, StationaryOneIgnoresTheObjectLocation) {
  // Tolerance 0 (bitwise): with Stationary = 1 the location is multiplied by 0.
  Rng rng(22);
  cg::Params base;
  base.set(cg::STATIONARY, 1.0f);
  const cg::Model m0 = cg::prepare(base);
  const float locations[][3] = {{5, 0, 0}, {-123.25f, 7, 1e4f}, {1e6f, -1e6f, 3e5f}, {1e7f, 1e7f, -1e7f}};
  for (const auto& l : locations) {
    cg::Params p = base;
    p.set(cg::OBJECT_LOCATION, l, 3);
    const cg::Model m = cg::prepare(p);
    for (int i = 0; i < 5000; ++i) {
      const vec3 x(rng.uniformf(-1, 1), rng.uniformf(-1, 1), rng.uniformf(-1, 1));
      ASSERT_TRUE(same_bits(cg::density(m, x), cg::density(m0, x)))
          << "at " << cgtest::str(x) << " location (" << l[0] << ", " << l[1] << ", " << l[2] << ")";
    }
  }
}

TEST(Model, StationaryZeroKeepsTheTextureFixedInTheWorld) {
  // Stationary = 0: N at local p with the object at L equals N at local p + L with the
  // object at the origin. Tolerance 2e-3: the offsets are reduced modulo 256 lattice
  // cells, so both sides see coordinates up to 256 with ulp 3e-5, times the largest
  // slope of N per lattice unit seen empirically (~20; the analytic bound is larger).
  Rng rng(23);
  cg::Params base;
  base.set(cg::STATIONARY, 0.0f);
  const cg::Model m0 = cg::prepare(base);
  double worst = 0;
  for (const vec3 l : {vec3(0.75f, 0, 0), vec3(-3.5f, 2.25f, 1), vec3(12.3f, -7.1f, 0.4f)}) {
    cg::Params p = base;
    const float lv[3] = {l[0], l[1], l[2]};
    p.set(cg::OBJECT_LOCATION, lv, 3);
    const cg::Model m = cg::prepare(p);
    for (int i = 0; i < 3000; ++i) {
      const vec3 x(rng.uniformf(-1, 1), rng.uniformf(-1, 1), rng.uniformf(-1, 1));
      const double a = double(cg::noise_at(m, x)), b = double(cg::noise_at(m0, x + l));
      worst = std::max(worst, std::fabs(a - b));
      ASSERT_NEAR(a, b, 2e-3) << "at " << cgtest::str(x) << " location " << cgtest::str(l);
    }
  }
  std::cout << "[ figures  ] stationary 0: largest |N(p; L) - N(p + L; 0)| = " << worst << "\n";
}

TEST(Model, WindMovesEveryNoiseLayer) {
  // Wind velocity v = strength * direction / |direction|; the texture drifts along v:
  // N(p, t) == N(p - v t, 0) (Stationary 1, Evolution 0 so time enters only through
  // the wind). Tolerance 2e-3 as above (wrapped offsets, coordinates up to 256).
  // The shape does not move. Checked with the Worley layer alone, the gradient-noise
  // layer alone, the wave layer and all together; a scaled direction (half as long) gives the same field.
  struct Layers {
    float worley_influence, noise_influence, wave;
  };
  const Layers layers[] = {{1, 0, 0}, {0, 1, 0}, {1, 0, 1}, {0.8f, 0.6f, 0.3f}};
  Rng rng(24);
  double worst = 0;
  for (const Layers& L : layers) {
    for (float t : {0.5f, 3.3f, -7.0f}) {
      cg::Params p;
      p.set(cg::WORLEY_INFLUENCE, L.worley_influence);
      p.set(cg::NOISE_INFLUENCE, L.noise_influence);
      p.set(cg::WAVE, L.wave);
      p.set(cg::EVOLUTION, 0.0f);
      p.set(cg::WIND_STRENGTH, 0.7f);
      const float dir[3] = {0.5f, 1.0f, -0.25f};
      p.set(cg::WIND_DIRECTION, dir, 3);
      cg::Params p0 = p;
      p.set(cg::TIME, t);
      const cg::Model mt = cg::prepare(p), m0 = cg::prepare(p0);
      const double len = std::sqrt(0.25 + 1.0 + 0.0625);
      const double td = double(t);
      const vec3 vt(float(0.7 * 0.5 / len * td), float(0.7 * 1.0 / len * td), float(0.7 * -0.25 / len * td));
      cg::Params p2 = p;  // the same direction, half as long
      const float dir2[3] = {0.25f, 0.5f, -0.125f};
      p2.set(cg::WIND_DIRECTION, dir2, 3);
      const cg::Model m2 = cg::prepare(p2);
      double moved = 0;
      for (int i = 0; i < 2000; ++i) {
        const vec3 x(rng.uniformf(-1, 1), rng.uniformf(-1, 1), rng.uniformf(-1, 1));
        const double a = double(cg::noise_at(mt, x)), b = double(cg::noise_at(m0, x - vt));
        worst = std::max(worst, std::fabs(a - b));
        moved = std::max(moved, std::fabs(a - double(cg::noise_at(m0, x))));
        ASSERT_NEAR(a, b, 2e-3) << "at " << cgtest::str(x) << " t " << t << " params " << cgtest::describe(p);
        ASSERT_NEAR(double(cg::noise_at(m2, x)), a, 2e-3) << "scaled direction, at " << cgtest::str(x);
        ASSERT_EQ(cg::shape_at(mt, x), cg::shape_at(m0, x)) << "the shape must not move with the wind";
      }
      EXPECT_GT(moved, 0.05) << "wind did not move the field: " << cgtest::describe(p);
    }
  }
  std::cout << "[ figures  ] wind: largest |N(p, t) - N(p - v t, 0)| = " << worst << "\n";
}

}  // namespace
