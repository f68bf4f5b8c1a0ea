// test_grid.cpp — the voxel grid (grid.h): sparse bake == dense bake (skip
// correctness), the region bound, grid_for_box, slices, LOD, cancellation,
// the memory estimate and the ring of a nested bake.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "cloudgen/field_key.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/param_io.h"
#include "test_util.h"

namespace {

using cg::vec3;
using cgtest::Rng;

struct Named {
  std::string name;
  cg::Params params;
};

cg::Params cumulus() {
  const cg::Preset* p = cg::find_preset("cumulus");
  EXPECT_NE(p, nullptr) << "preset 'cumulus' missing";
  return p ? p->params : cg::Params();
}

std::vector<Named> parameter_sets() {
  std::vector<Named> sets;
  sets.push_back({"cumulus", cumulus()});
  cg::Params p = cumulus();
  p.set(cg::DISTORTION, 2.0f);
  p.set(cg::NOISE_WHISP, 1.0f);
  sets.push_back({"high distortion", p});
  p = cumulus();
  p.set(cg::CLOUD_SCALE, 0.15f);
  sets.push_back({"small cloud_scale", p});
  p = cg::Params();
  p.set(cg::SHAPE_MODE, 1.0f);
  sets.push_back({"curve profile", p});
  for (float e : {0.3f, 3.0f}) {
    p = cg::Params();
    p.set(cg::SHAPE_MODE, 0.0f);
    p.set(cg::SHAPE_EXPONENT, e);
    const float box[3] = {3, 2, 1.5f};
    p.set(cg::BOX_SIZE, box, 3);
    sets.push_back({"exponent profile " + std::to_string(e), p});
  }
  // The shape terms: flat base and top, lean both ways, sheet, edge, turrets, warp.
  p = cumulus();
  p.set(cg::BASE_HEIGHT, 0.1f);
  p.set(cg::TOP_HEIGHT, 0.8f);
  p.set(cg::LEAN, 0.6f);
  p.set(cg::EDGE_SHARPNESS, 0.8f);
  p.set(cg::TURRET_INFLUENCE, 0.5f);
  sets.push_back({"base, top, lean", p});
  p.set(cg::LEAN, -1.5f);
  p.set(cg::SHEAR, -1.0f);
  p.set(cg::STRETCH, 4.0f);
  sets.push_back({"lean back, sheared", p});
  p = cg::Params();
  p.set(cg::SHEET, 1.0f);
  p.set(cg::SHAPE_MODE, 1.0f);
  const float layer[3] = {40, 30, 1.5f};
  p.set(cg::BOX_SIZE, layer, 3);
  sets.push_back({"sheet", p});
  p.set(cg::SHEET, 0.4f);
  p.set(cg::BASE_HEIGHT, 0.3f);
  sets.push_back({"half sheet with a base", p});
  // The anvil: narrowed below its height, under a ceiling and leaning; then with no ceiling, the flare
  // squeezed into its 1 % minimum at the top (an Anvil Height of 1).
  p = cg::find_preset("cumulonimbus")->params;
  sets.push_back({"cumulonimbus anvil", p});
  p = cumulus();
  p.set(cg::ANVIL, 1.0f);
  p.set(cg::ANVIL_HEIGHT, 1.0f);
  p.set(cg::LEAN, -0.7f);
  sets.push_back({"anvil at the very top", p});
  return sets;
}

using cgtest::to_dense;

int test_resolution() { return cgtest::sanitize() ? 32 : 48; }

cg::BakeResult run_bake(const cg::Model& m, int res, bool skip, bool lod) {
  cg::BakeOptions o;
  o.resolution = res;
  o.skip_empty = skip;
  o.lod = lod;
  o.threads = 2;
  return cg::bake(m, o);
}

TEST(Grid, SparseBakeEqualsDenseBake) {
  // Tolerance 0: voxel for voxel, a skipped tile holds no positive density.
  const int res = test_resolution();
  for (const Named& s : parameter_sets()) {
    const cg::Model m = cg::prepare(s.params);
    const cg::BakeResult sparse = run_bake(m, res, true, false), dense = run_bake(m, res, false, false);
    ASSERT_EQ(dense.stats.tiles_skipped, 0);
    const std::vector<float> a = to_dense(sparse), b = to_dense(dense);
    ASSERT_EQ(a.size(), b.size());
    std::int64_t active = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      active += b[i] > 0.0f;
      const int x = int(i % std::size_t(sparse.grid.n[0]));
      const int y = int((i / std::size_t(sparse.grid.n[0])) % std::size_t(sparse.grid.n[1]));
      const int z = int(i / (std::size_t(sparse.grid.n[0]) * std::size_t(sparse.grid.n[1])));
      ASSERT_EQ(a[i], b[i]) << s.name << ": voxel (" << x << ", " << y << ", " << z << ") sparse " << a[i] << " dense "
                            << b[i] << " params " << cgtest::describe(s.params);
    }
    EXPECT_GT(active, 0) << s.name;
    std::cout << "[ figures  ] " << s.name << " at " << res << ": tiles " << sparse.stats.tiles_total << ", skipped "
              << sparse.stats.tiles_skipped << ", active voxels " << active << "\n";
    // The cumulus preset fills its box (a wide, flat-bottomed profile), so at 32 its
    // corner tiles hold cloud; a small cloud and a raised base leave tiles provably empty.
    if (s.name == "small cloud_scale" || s.name == "base, top, lean") {
      EXPECT_GT(sparse.stats.tiles_skipped, 0) << s.name << " should skip some tiles";
    }
  }
}

TEST(Grid, EveryTileTheBoundProvesEmptyIsEmpty) {
  // Tolerance 0: for every tile with shape_upper_bound <= 0 (over its voxel centres),
  // every voxel centre has density 0 and shape + |F|/2 <= 0. Resolution 64 (cheap: the
  // voxels of proven tiles never reach the noise); the cumulus must have proven tiles.
  const int res = 64;
  int proven_total = 0;
  for (const Named& s : parameter_sets()) {
    const cg::Model m = cg::prepare(s.params);
    const cg::GridSpec g = cg::grid_for_box(m, res);
    int proven = 0;
    for (int tz = 0; tz < g.tiles(2); ++tz)
      for (int ty = 0; ty < g.tiles(1); ++ty)
        for (int tx = 0; tx < g.tiles(0); ++tx) {
          const int lo[3] = {tx * cg::kTile, ty * cg::kTile, tz * cg::kTile};
          const int hi[3] = {std::min(lo[0] + cg::kTile, g.n[0]), std::min(lo[1] + cg::kTile, g.n[1]),
                             std::min(lo[2] + cg::kTile, g.n[2])};
          const float bound =
              cg::shape_upper_bound(m, g.centre(lo[0], lo[1], lo[2]), g.centre(hi[0] - 1, hi[1] - 1, hi[2] - 1));
          if (bound > 0.0f) continue;
          ++proven;
          for (int k = lo[2]; k < hi[2]; ++k)
            for (int j = lo[1]; j < hi[1]; ++j)
              for (int i = lo[0]; i < hi[0]; ++i) {
                const vec3 p = g.centre(i, j, k);
                ASSERT_EQ(cg::density(m, p), 0.0f)
                    << s.name << ": voxel (" << i << ", " << j << ", " << k << ") at " << cgtest::str(p)
                    << " in a tile proven empty (bound " << bound << ")";
                if (cg::inside_box(cg::generated(m, p))) {
                  ASSERT_LE(cg::shape_at(m, p) + 0.5f * std::fabs(m.distortion), 0.0f)
                      << s.name << " at " << cgtest::str(p);
                }
              }
        }
    if (s.name == "cumulus") {
      EXPECT_GT(proven, 0) << s.name << ": no tile proven empty";
    }
    proven_total += proven;
  }
  std::cout << "[ figures  ] tiles proven empty at 64 over all parameter sets: " << proven_total << "\n";
}

TEST(Grid, ShapeUpperBoundBoundsEveryPointOfItsRegion) {
  // Tolerance 0: shape(p) + |F|/2 <= shape_upper_bound(lo, hi) for points p in random
  // regions [lo, hi] (inside the box), including the region's corners and faces.
  Rng rng(31);
  for (const Named& s : parameter_sets()) {
    const cg::Model m = cg::prepare(s.params);
    for (int r = 0; r < 2000; ++r) {
      vec3 lo, hi;
      for (int a = 0; a < 3; ++a) {
        const double half = 0.6 * double(m.box[a]);
        const double u = rng.uniform(-half, half), w = rng.uniform(0, 0.3 * double(m.box[a]));
        lo[a] = float(u);
        hi[a] = float(u + w);
      }
      const float bound = cg::shape_upper_bound(m, lo, hi);
      for (int q = 0; q < 20; ++q) {
        vec3 p;
        for (int a = 0; a < 3; ++a) {
          const int pick = rng.integer(0, 3);
          p[a] = pick == 0 ? lo[a] : pick == 1 ? hi[a] : rng.uniformf(double(lo[a]), double(hi[a]));
        }
        if (!cg::inside_box(cg::generated(m, p))) continue;
        ASSERT_LE(cg::shape_at(m, p) + 0.5f * std::fabs(m.distortion), bound)
            << s.name << ": point " << cgtest::str(p) << " region " << cgtest::str(lo) << " - " << cgtest::str(hi);
      }
    }
  }
}

TEST(Grid, GridForBoxHasCubicVoxelsAndNAlongTheLongestSide) {
  // Exact: N voxels along the longest side; the grid covers the box and overhangs a
  // shorter side by less than one voxel; it is centred on the box (to 1e-5 relative).
  const float boxes[][3] = {{4, 4, 3}, {1, 7, 2.5f}, {3, 3, 3}, {0.2f, 0.05f, 0.1f}, {1000, 10, 250}};
  for (const auto& b : boxes) {
    cg::Params p;
    p.set(cg::BOX_SIZE, b, 3);
    const cg::Model m = cg::prepare(p);
    for (int res : {1, 7, 64, 200}) {
      const cg::GridSpec g = cg::grid_for_box(m, res);
      const int longest = int(std::max_element(b, b + 3) - b);
      EXPECT_EQ(g.n[longest], res) << "box (" << b[0] << ", " << b[1] << ", " << b[2] << ") resolution " << res;
      EXPECT_NEAR(double(g.voxel), double(b[longest]) / res, 1e-6 * double(b[longest]) / res);
      for (int a = 0; a < 3; ++a) {
        const double extent = double(g.n[a]) * double(g.voxel);
        EXPECT_GE(extent, double(b[a]) * (1 - 1e-4)) << "axis " << a << " resolution " << res;
        EXPECT_LT(extent, double(b[a]) + double(g.voxel)) << "axis " << a << " resolution " << res;
        EXPECT_NEAR(double(g.origin[a]), -0.5 * extent, 1e-5 * extent) << "axis " << a;
      }
    }
  }
}

TEST(Grid, SliceEqualsDensityAtSlicePoints) {
  // Tolerance 0 (lod off): every pixel equals cg::density at cg::slice_point, and the
  // slice points lie on the plane, inside the box, at pixel centres.
  const cg::Model m = cg::prepare(cumulus());
  for (int axis = 0; axis < 3; ++axis)
    for (float offset : {0.5f, 0.3f}) {
      cg::SliceSpec s;
      s.axis = axis;
      s.offset = offset;
      s.width = 40;
      s.height = 24;
      s.threads = 2;
      const std::vector<float> img = cg::slice(m, s);
      ASSERT_EQ(img.size(), std::size_t(40 * 24));
      double sum = 0;
      for (int row = 0; row < s.height; ++row)
        for (int col = 0; col < s.width; ++col) {
          const vec3 p = cg::slice_point(m, s, col, row);
          const vec3 g = cg::generated(m, p);
          ASSERT_NEAR(double(g[axis]), double(offset), 1e-6) << "axis " << axis;
          ASSERT_TRUE(cg::inside_box(g)) << cgtest::str(p);
          ASSERT_EQ(img[std::size_t(row) * 40 + col], cg::density(m, p))
              << "axis " << axis << " offset " << offset << " pixel (" << col << ", " << row << ")";
          sum += double(img[std::size_t(row) * 40 + col]);
        }
      if (offset == 0.5f) {
        EXPECT_GT(sum, 0.0) << "the centre slice of the cumulus should not be empty";
      }
      // Row 0 is the top: its points have the largest row coordinate.
      int ca, ra;
      cg::slice_axes(axis, ca, ra);
      EXPECT_GT(cg::slice_point(m, s, 0, 0)[ra], cg::slice_point(m, s, 0, 1)[ra]);
      EXPECT_LT(cg::slice_point(m, s, 0, 0)[ca], cg::slice_point(m, s, 1, 0)[ca]);
    }
}

TEST(Grid, LevelOfDetail) {
  // LOD octave counts fall as the resolution falls (non-increasing, and strictly
  // over 512 -> 16), and the bake reports the ones it used. The LOD bake of the
  // cumulus differs from the full one by an RMS below 0.05 x the RMS of the density
  // (measured: see the figures line; the dropped octaves are the finest ones).
  // Edge Sharpness 0: the edge remap multiplies any change of the raw value near the
  // boundary by up to 1/w (12.5), so at the preset's 0.85 the same octaves move the
  // sharp edges by a voxel here and there (RMS 0.06 measured) — that is the edge, not the LOD.
  cg::Params p = cumulus();
  p.set(cg::EDGE_SHARPNESS, 0.0f);
  const cg::Model m = cg::prepare(p);
  float prev_w = CG_MAX_OCTAVES + 1, prev_p = CG_MAX_OCTAVES + 1;
  for (int res : {1024, 512, 256, 128, 64, 32, 16, 8}) {
    const cg::Lod lod = cg::lod_for_footprint(m, cg::grid_for_box(m, res).voxel);
    EXPECT_LE(lod.worley_octaves, prev_w) << "resolution " << res;
    EXPECT_LE(lod.perlin_octaves, prev_p) << "resolution " << res;
    EXPECT_GE(lod.worley_octaves, 1.0f);
    prev_w = lod.worley_octaves;
    prev_p = lod.perlin_octaves;
  }
  const cg::Lod hi = cg::lod_for_footprint(m, cg::grid_for_box(m, 512).voxel);
  const cg::Lod lo = cg::lod_for_footprint(m, cg::grid_for_box(m, 16).voxel);
  EXPECT_GT(hi.perlin_octaves, lo.perlin_octaves);
  EXPECT_GT(hi.worley_octaves, lo.worley_octaves);
  const cg::Lod none = cg::lod_for_footprint(m, 0.0f);
  EXPECT_EQ(none.perlin_octaves, float(CG_MAX_OCTAVES));

  // 48^3 at every test scale (a few ms, tens under ASan): at the sanitizer scale's 32^3 the LOD keeps
  // 1.1 of 5 gradient octaves and the 5 % bound below no longer describes a useful level of detail
  // (measured 6.4 % there, 3.9 % at 48^3)
  const int res = 48;
  const cg::BakeResult with = run_bake(m, res, true, true), without = run_bake(m, res, true, false);
  const cg::Lod used = cg::lod_for_footprint(m, with.grid.voxel);
  EXPECT_EQ(with.stats.lod_perlin_octaves, used.perlin_octaves);
  EXPECT_EQ(with.stats.lod_worley_octaves, used.worley_octaves);
  const std::vector<float> a = to_dense(with), b = to_dense(without);
  double diff2 = 0, ref2 = 0, worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff2 += (double(a[i]) - double(b[i])) * (double(a[i]) - double(b[i]));
    ref2 += double(b[i]) * double(b[i]);
    worst = std::max(worst, std::fabs(double(a[i]) - double(b[i])));
  }
  const double rms = std::sqrt(diff2 / double(a.size())), ref = std::sqrt(ref2 / double(a.size()));
  std::cout << "[ figures  ] LOD at " << res << "^3 (perlin " << used.perlin_octaves << " of 5 octaves, worley "
            << used.worley_octaves << " of 2): RMS difference " << rms << " = " << rms / ref << " of the density RMS "
            << ref << ", largest " << worst << "\n";
  EXPECT_GT(rms, 0.0) << "LOD dropped nothing at this resolution";
  EXPECT_LT(rms, 0.05 * ref);
}

TEST(Grid, ProgressReturningFalseCancelsTheBake) {
  const cg::Model m = cg::prepare(cumulus());
  cg::BakeOptions o;
  o.resolution = 16;
  o.threads = 2;
  int calls = 0;
  EXPECT_THROW(cg::bake(m, o,
                        [&](std::int64_t, std::int64_t) {
                          ++calls;
                          return false;
                        }),
               cg::Cancelled);
  EXPECT_GT(calls, 0);
  // A progress that says yes gets the final call with done == total.
  std::int64_t last_done = -1, last_total = -2;
  const cg::BakeResult r = cg::bake(m, o, [&](std::int64_t d, std::int64_t t) {
    last_done = d;
    last_total = t;
    return true;
  });
  EXPECT_EQ(last_done, last_total);
  EXPECT_EQ(last_total, r.stats.tiles_total);
}

TEST(Grid, EstimateGrowsWithResolutionAndCoversTheTiles) {
  const cg::Model m = cg::prepare(cumulus());
  std::int64_t prev = 0;
  for (int res : {8, 16, 32, 64, 128, 256}) {
    cg::BakeOptions o;
    o.resolution = res;
    const std::int64_t e = cg::estimate_bake_bytes(m, o);
    EXPECT_GT(e, prev) << "resolution " << res;
    prev = e;
    if (res <= 64) {
      o.threads = 2;
      const cg::BakeResult r = cg::bake(m, o);
      const std::int64_t actual = std::int64_t(r.tiles.size()) * std::int64_t(sizeof(cg::Tile));
      EXPECT_GE(e, actual) << "resolution " << res;
      o.skip_empty = false;
      EXPECT_GE(cg::estimate_bake_bytes(m, o), e) << "skip_empty = false is the worst case";
    }
  }
}

// A flat layer, 40 x 30 x 1.5, reaching the box's sides (a deck baked as nested rings).
cg::Params layer() {
  cg::Params p;
  p.set(cg::SHEET, 1.0f);
  p.set(cg::SHAPE_MODE, 1.0f);
  const float box[3] = {40, 30, 1.5f};
  p.set(cg::BOX_SIZE, box, 3);
  return p;
}

TEST(Grid, RingBakeEqualsTheWholeBakeInTheRingAndIsEmptyElsewhere) {
  // Tolerance 0: with c = max(|x|, |y|) of a voxel centre, every voxel with
  // inner - voxel <= c < outer + voxel equals the whole bake's bit for bit (same grid,
  // same LOD), every other voxel is 0; tiles whose footprint widened by a voxel lies
  // wholly in the hole or beyond the outer square are culled (never evaluated), and the
  // memory estimate counts exactly the tiles the bake evaluates.
  const cg::Model m = cg::prepare(layer());
  cg::BakeOptions whole;
  whole.resolution = 96;  // voxel 40/96, 96x72x4 voxels, 12x9x1 tiles of 3.33 x 3.33
  whole.threads = 2;
  const cg::BakeResult a = cg::bake(m, whole);
  const std::vector<float> da = to_dense(a);
  const std::int64_t est_whole = cg::estimate_bake_bytes(m, whole);
  const float inf = std::numeric_limits<float>::infinity();
  // A ring, an open ring (no outer limit), a disc (no hole), a ring thinner than 2 voxels, and
  // two whose bounds lie just beyond a tile's edge (|y| = 5), so that the tile is culled unless
  // it is widened by a voxel, yet holds voxels of the margin (centres at |y| = 4.79 and 5.21).
  const float rings[][2] = {{6, 14}, {6, inf}, {0, 9}, {2.5f, 3}, {5.2f, 12}, {0.5f, 4.8f}};
  for (const auto& ring : rings) {
    cg::BakeOptions o = whole;
    o.ring_inner = ring[0];
    o.ring_outer = ring[1];
    std::ostringstream what_text;
    what_text << "ring [" << ring[0] << ", " << ring[1] << ")";
    const std::string what = what_text.str();
    const cg::BakeResult b = cg::bake(m, o);
    const cg::GridSpec& g = b.grid;
    ASSERT_EQ(g.voxel, a.grid.voxel) << what;
    const std::vector<float> db = to_dense(b);
    ASSERT_EQ(db.size(), da.size());
    std::int64_t in_ring = 0, outside = 0;
    for (int k = 0; k < g.n[2]; ++k)
      for (int j = 0; j < g.n[1]; ++j)
        for (int i = 0; i < g.n[0]; ++i) {
          const std::size_t q = (std::size_t(k) * g.n[1] + j) * g.n[0] + i;
          const vec3 p = g.centre(i, j, k);
          const float c = std::max(std::fabs(p[0]), std::fabs(p[1]));
          const bool kept = c >= ring[0] - g.voxel && c < ring[1] + g.voxel;
          ASSERT_EQ(db[q], kept ? da[q] : 0.0f)
              << what << ": voxel (" << i << ", " << j << ", " << k << ") at " << cgtest::str(p) << " c " << c
              << " voxel " << g.voxel << (kept ? " in the ring" : " outside the ring") << ", whole bake " << da[q];
          (kept ? in_ring : outside) += da[q] > 0.0f;
        }
    EXPECT_GT(in_ring, 0) << what << ": no cloud in the ring";
    EXPECT_GT(outside, 0) << what << ": no cloud outside the ring, nothing was dropped";
    EXPECT_EQ(b.stats.voxels_active, in_ring) << what;
    EXPECT_GT(b.stats.tiles_culled, 0) << what << ": no tile culled";
    EXPECT_LT(b.stats.tiles_evaluated, a.stats.tiles_evaluated) << what;
    EXPECT_EQ(b.stats.tiles_culled + b.stats.tiles_skipped + b.stats.tiles_evaluated, b.stats.tiles_total) << what;
    const std::int64_t est = cg::estimate_bake_bytes(m, o);
    EXPECT_LE(est, est_whole) << what;
    // Exact: the estimate is a fixed size per tile it counts, and it counts the evaluated tiles.
    EXPECT_EQ(est * a.stats.tiles_evaluated, est_whole * b.stats.tiles_evaluated) << what;
    EXPECT_NE(cg::bake_key(m, o, false), cg::bake_key(m, whole, false)) << what;
    std::cout << "[ figures  ] " << what << " at 96: tiles culled " << b.stats.tiles_culled << ", evaluated "
              << b.stats.tiles_evaluated << " (whole bake " << a.stats.tiles_evaluated << " of " << a.stats.tiles_total
              << "), active voxels " << b.stats.voxels_active << " of " << a.stats.voxels_active << "\n";
  }
  // The hole of [6, 14): 2 x 3 tiles (x in [-3.33, 3.33], y in [-5, 5], widened by 0.42 < 6).
  cg::BakeOptions o = whole;
  o.ring_inner = 6;
  EXPECT_EQ(cg::bake(m, o).stats.tiles_culled, 6) << "the open ring [6, inf) culls the 2 x 3 tiles of its hole";
}

TEST(Grid, DefaultRingIsNoRing) {
  // The default options bake what they baked before the ring existed: no ring, the same key
  // as an explicit (0, +inf), and a ring enclosing the whole box keeps every voxel
  // (tolerance 0) and culls nothing, under another key.
  const cg::Model m = cg::prepare(cumulus());
  cg::BakeOptions d;
  d.resolution = 32;
  d.threads = 2;
  EXPECT_FALSE(d.has_ring());
  EXPECT_EQ(d.ring_inner, 0.0f);
  EXPECT_EQ(d.ring_outer, std::numeric_limits<float>::infinity());
  cg::BakeOptions wide = d;
  wide.ring_outer = 100.0f;  // the 4 x 4 box lies within max(|x|, |y|) <= 2
  ASSERT_TRUE(wide.has_ring());
  const cg::BakeResult a = cg::bake(m, d), b = cg::bake(m, wide);
  EXPECT_EQ(a.stats.tiles_culled, 0);
  EXPECT_EQ(b.stats.tiles_culled, 0);
  EXPECT_EQ(b.stats.voxels_active, a.stats.voxels_active);
  ASSERT_EQ(a.tiles.size(), b.tiles.size());
  for (std::size_t t = 0; t < a.tiles.size(); ++t) {
    ASSERT_EQ(a.tiles[t].index, b.tiles[t].index) << "tile " << t;
    ASSERT_EQ(0, std::memcmp(a.tiles[t].values.data(), b.tiles[t].values.data(), sizeof a.tiles[t].values))
        << "tile " << t;
  }
  EXPECT_EQ(cg::estimate_bake_bytes(m, wide), cg::estimate_bake_bytes(m, d));
  EXPECT_NE(cg::bake_key(m, wide, false), cg::bake_key(m, d, false)) << "a ring bake must never match a plain one";
}

}  // namespace
