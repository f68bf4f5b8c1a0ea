// test_supersample.cpp — the box-filtered bake (BakeOptions::supersample, grid.h):
// k = 1 is the point-sampled bake, a voxel of k > 1 is the mean of its k^3
// sub-samples, sparse == dense with the sub-samples' reach, the key and the
// statistics, and the reason it exists: for a thin layer of thresholded noise
// (the cirrocumulus preset) a box-filtered voxel is nearer its cell's true mean
// than a point sample, so the bake carries less aliasing (docs/gallery/moire).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "cloudgen/field_key.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/param_io.h"
#include "test_util.h"

namespace {

using cg::vec3;

using cgtest::preset;

using cgtest::dense_index;
using cgtest::to_dense;

// The mean density over voxel (x, y, z)'s cell, from n^3 samples on a regular sub-grid of
// the cell's part inside the box (the density is 0 outside it), times that part's share of
// the cell's volume.
double cell_mean(const cg::Model& m, const cg::GridSpec& g, int x, int y, int z, int n, const cg::Lod& lod) {
  const vec3 c = g.centre(x, y, z);
  float lo[3], span[3];
  bool clipped[3];
  double share = 1.0;
  for (int a = 0; a < 3; ++a) {
    const float half = 0.5f * m.box[a];
    clipped[a] = c[a] - 0.5f * g.voxel < -half || c[a] + 0.5f * g.voxel > half;
    lo[a] = std::max(c[a] - 0.5f * g.voxel, -half);
    span[a] = std::max(std::min(c[a] + 0.5f * g.voxel, half) - lo[a], 0.0f);
    share *= double(span[a]) / double(g.voxel);
  }
  double sum = 0.0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int d = 0; d < n; ++d) {
        const auto at = [&](int axis, int s) {  // an unclipped axis: offsets from the centre, as the bake
          return clipped[axis] ? lo[axis] + (float(s) + 0.5f) / float(n) * span[axis]
                               : c[axis] + ((float(s) + 0.5f) / float(n) - 0.5f) * g.voxel;
        };
        sum += double(cg::density(m, {at(0, d), at(1, b), at(2, a)}, lod));
      }
  return share * sum / double(n * n * n);
}

// A box-filtered bake (k per axis) of the central square |x|, |y| < half at a given voxel.
cg::BakeResult square_bake(const cg::Model& m, float voxel, float half, int k) {
  cg::BakeOptions o;
  o.voxel = voxel;
  o.ring_outer = half;
  o.threads = 2;
  o.supersample = k;
  return cg::bake(m, o);
}

TEST(Supersample, OneIsThePointSampledBake) {
  // Bitwise: supersample 1 (and an out-of-range 0, clamped to 1) bakes what the default bakes, under its key.
  const cg::Model m = cg::prepare(preset("cumulus"));
  cg::BakeOptions d;
  d.resolution = 32;
  d.threads = 2;
  const std::vector<float> a = to_dense(cg::bake(m, d));
  for (int k : {0, 1}) {
    cg::BakeOptions o = d;
    o.supersample = k;
    const std::vector<float> b = to_dense(cg::bake(m, o));
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "supersample " << k << ", voxel " << i;
  }
  for (int k : {0, 1}) {
    cg::BakeOptions one = d;
    one.supersample = k;
    EXPECT_EQ(cg::bake_key(m, one, false), cg::bake_key(m, d, false))
        << "supersample " << k << ": the point bake's key";
  }
  // Above kMaxSupersample the bake and its key are those of kMaxSupersample (one clamp rule).
  cg::BakeOptions most = d, beyond = d;
  most.supersample = cg::kMaxSupersample;
  beyond.supersample = cg::kMaxSupersample + 5;
  EXPECT_EQ(cg::bake_key(m, beyond, false), cg::bake_key(m, most, false));
  const std::vector<float> c = to_dense(cg::bake(m, most)), e = to_dense(cg::bake(m, beyond));
  for (std::size_t i = 0; i < c.size(); ++i)
    ASSERT_EQ(c[i], e[i]) << "supersample " << beyond.supersample << ", voxel " << i;
}

TEST(Supersample, VoxelIsTheMeanOfItsSubSamples) {
  // Every voxel of a k = 2 and k = 3 bake equals the mean of cg::density at its k^3 sub-sample
  // points (cell centres of a k-split of the voxel), LOD at voxel / k; tolerance 5e-6 relative
  // (the same float sums in another order); outside a ring bake's square (and its one voxel of
  // margin) 0. A sparse bake equals the dense one bitwise: the tile
  // skip widens its bound by the sub-samples' reach.
  for (const char* name : {"cumulus", "cirrocumulus"}) {
    const cg::Model m = cg::prepare(preset(name));
    for (int k : {2, 3}) {
      cg::BakeOptions o;
      o.threads = 2;
      if (std::string(name) == "cumulus") {
        o.resolution = cgtest::sanitize() ? 16 : 24;
      } else {  // the 0.6-unit layer: 5 voxels thick, the central 4 x 4 square (a ring bake)
        o.voxel = 0.12f;
        o.ring_outer = 2.0f;
      }
      o.supersample = k;
      const cg::BakeResult r = cg::bake(m, o);
      const std::vector<float> a = to_dense(r);
      const cg::Lod lod = cg::lod_for_footprint(m, r.grid.voxel / float(k));
      EXPECT_EQ(r.stats.lod_worley_octaves, lod.worley_octaves) << name << " k " << k;
      EXPECT_EQ(r.stats.samples_evaluated, r.stats.voxels_evaluated * k * k * k) << name << " k " << k;
      std::int64_t active = 0;
      for (int z = 0; z < r.grid.n[2]; ++z)
        for (int y = 0; y < r.grid.n[1]; ++y)
          for (int x = 0; x < r.grid.n[0]; ++x) {
            const float got = a[dense_index(r.grid, x, y, z)];
            const vec3 c = r.grid.centre(x, y, z);
            const bool kept = std::max(std::fabs(c[0]), std::fabs(c[1])) < o.ring_outer + r.grid.voxel;
            const double want = kept ? cell_mean(m, r.grid, x, y, z, k, lod) : 0.0;
            active += got > 0.0f;
            ASSERT_NEAR(got, want, 5e-6 * std::max(1.0, std::fabs(want)))
                << name << ", supersample " << k << ", voxel (" << x << ", " << y << ", " << z << ") of " << r.grid.n[0]
                << "x" << r.grid.n[1] << "x" << r.grid.n[2] << ", voxel " << r.grid.voxel;
          }
      EXPECT_GT(active, 0) << name << " k " << k << ": empty bake";
      cg::BakeOptions dense = o;
      dense.skip_empty = false;
      const std::vector<float> b = to_dense(cg::bake(m, dense));
      for (std::size_t i = 0; i < a.size(); ++i)
        ASSERT_EQ(a[i], b[i]) << name << ", supersample " << k << ": sparse != dense at voxel " << i;
      cg::BakeOptions point = o;
      point.supersample = 1;
      EXPECT_NE(cg::bake_key(m, o, false), cg::bake_key(m, point, false)) << name << " k " << k;
    }
  }
}

TEST(Supersample, BoxFilteredThinLayerIsNearerTheCellMean) {
  // The cirrocumulus's central 10 x 10 square (its gallery ring) at the gallery's innermost voxel
  // (0.091 units, 7 voxels through the 0.6-unit layer). Reference: each voxel's true cell mean,
  // 6^3 samples without LOD, on every 7th voxel. The RMS error of the baked voxels against it,
  // printed with the reference's RMS: a box-filtered bake at k = 2 must be at least 2x nearer than
  // the point bake (measured 5.2x: 0.107 against 0.553, reference RMS 1.23; the preset's scale
  // 6), k = 3 no farther than k = 2 (measured 0.046). A column's error through the layer (the sum
  // over z, what a view from below integrates) must shrink 2x at k = 2 too (0.30 against 1.58).
  const cg::Model m = cg::prepare(preset("cirrocumulus"));
  const float half = cgtest::sanitize() ? 2.0f : 5.0f;
  const int stride = 7, reference_n = 6;
  double rms[4] = {}, column_rms[4] = {}, reference_rms = 0.0, column_reference_rms = 0.0;
  for (int k : {1, 2, 3}) {
    const cg::BakeResult r = square_bake(m, 0.091f, half, k);
    const std::vector<float> a = to_dense(r);
    const cg::GridSpec& g = r.grid;
    double err2 = 0.0, ref2 = 0.0, col_err2 = 0.0, col_ref2 = 0.0;
    std::int64_t n = 0, columns = 0;
    for (int y = 0; y < g.n[1]; y += stride)
      for (int x = 0; x < g.n[0]; x += stride) {
        const vec3 c = g.centre(x, y, 0);
        if (std::max(std::fabs(c[0]), std::fabs(c[1])) >= half - g.voxel) continue;
        double col = 0.0, col_ref = 0.0;
        for (int z = 0; z < g.n[2]; ++z) {
          const double want = cell_mean(m, g, x, y, z, reference_n, cg::kNoLod);
          const double got = a[dense_index(g, x, y, z)];
          err2 += (got - want) * (got - want);
          ref2 += want * want;
          col += got, col_ref += want;
          ++n;
        }
        col_err2 += (col - col_ref) * (col - col_ref);
        col_ref2 += col_ref * col_ref;
        ++columns;
      }
    ASSERT_GT(ref2, 0.0) << "the reference voxels are all empty";
    rms[k] = std::sqrt(err2 / double(n));
    column_rms[k] = std::sqrt(col_err2 / double(columns));
    reference_rms = std::sqrt(ref2 / double(n));
    column_reference_rms = std::sqrt(col_ref2 / double(columns));
    std::cout << "[ figures  ] cirrocumulus, voxel " << g.voxel << ", supersample " << k << ": RMS error " << rms[k]
              << " (reference RMS " << reference_rms << ") over " << n << " voxels; column RMS error " << column_rms[k]
              << " (reference " << column_reference_rms << ") over " << columns << " columns; samples "
              << r.stats.samples_evaluated << "\n";
  }
  EXPECT_LT(rms[2] * 2.0, rms[1]) << "k = 2 not 2x nearer the cell mean than the point bake";
  EXPECT_LT(rms[3], rms[2] * 1.05) << "k = 3 farther from the cell mean than k = 2";
  EXPECT_LT(column_rms[2] * 2.0, column_rms[1]) << "k = 2: columns not 2x nearer";
}

TEST(Supersample, LayerThinnerThanAVoxelKeepsItsColumn) {
  // The cirrostratus veil (0.5 units thick) at the gallery's outer voxels (0.8 and 3.2 units: one
  // voxel through the layer). A view through the layer sees its column, the voxel's density x
  // voxel. Reference per column: the mean over its cell's 4 x 4 sub-columns of the density's
  // integral over the box's height (midpoint rule, 100 samples, the bake's LOD). Every bake samples
  // the layer's part of the cell and weights it by the part's share: k midpoints through the layer
  // miss the profile's tapered top and bottom, measured +24 %/+22 % at k = 1, +20 %/+19 % at k = 2
  // and +12.4 %/+12.1 % at k = 3 in the sum (before the sheet's cap, 2026-12-03, which tapers the
  // top eighth further: +20/+18, +16/+15, +8.8/+8.5); tolerance 28 %, 22 % and 15 %; column RMS
  // error under 25 % at k > 1 (measured 12-20 %: k^2 sub-columns estimate the cell's mean
  // coarsely), 30 % at k = 1 (measured 24-25 %). The rule before 2026-11-27 (the density at the cell's centre times a
  // whole voxel: 1.93x and 7.6x the reference) must be off by more than 40 %, so the test tells the
  // two apart. The sanitizer scale keeps a square of 8 (at a voxel of 3.2, 9 whole columns; at 4,
  // none: the test then failed).
  const cg::Model m = cg::prepare(preset("cirrostratus"));
  const float half = cgtest::sanitize() ? 8.0f : 12.0f;  // at 3.2: 9 or 25 whole columns
  const int sub = 4, reference_n = 100;
  for (float voxel : {0.8f, 3.2f}) {
    for (int k : {1, 2, 3}) {
      const cg::BakeResult r = square_bake(m, voxel, half, k);
      const std::vector<float> a = to_dense(r);
      const cg::GridSpec& g = r.grid;
      const cg::Lod lod = cg::lod_for_footprint(m, voxel / float(k));
      ASSERT_EQ(g.n[2], 1) << "voxel " << voxel << ": the layer is not one voxel thick";
      const double h = double(m.box[2]);
      double err2 = 0.0, ref2 = 0.0, sum = 0.0, sum_ref = 0.0, sum_centre = 0.0;
      std::int64_t columns = 0;
      for (int y = 0; y < g.n[1]; ++y)
        for (int x = 0; x < g.n[0]; ++x) {
          const vec3 c = g.centre(x, y, 0);
          if (std::max(std::fabs(c[0]), std::fabs(c[1])) >= half - g.voxel) continue;
          double col_ref = 0.0;
          for (int j = 0; j < sub; ++j)
            for (int i = 0; i < sub; ++i)
              for (int l = 0; l < reference_n; ++l) {
                const float px = c[0] + ((float(i) + 0.5f) / float(sub) - 0.5f) * voxel;
                const float py = c[1] + ((float(j) + 0.5f) / float(sub) - 0.5f) * voxel;
                const float pz = float(-0.5 * h + (l + 0.5) / reference_n * h);
                col_ref += double(cg::density(m, {px, py, pz}, lod));
              }
          col_ref *= h / double(reference_n * sub * sub);
          const double col = double(a[dense_index(g, x, y, 0)]) * double(g.voxel);
          err2 += (col - col_ref) * (col - col_ref);
          ref2 += col_ref * col_ref;
          sum += col, sum_ref += col_ref;
          sum_centre += double(cg::density(m, c, lod)) * double(g.voxel);
          ++columns;
        }
      ASSERT_GT(sum_ref, 0.0) << "voxel " << voxel << ": the reference columns are all empty";
      const double rms = std::sqrt(err2 / ref2), ratio = sum / sum_ref;
      std::cout << "[ figures  ] cirrostratus, voxel " << voxel << ", supersample " << k << ": columns' sum " << ratio
                << " of the reference's, column RMS error " << rms << " of the reference RMS "
                << std::sqrt(ref2 / double(columns)) << ", " << columns << " columns\n";
      if (k == 1) {
        EXPECT_GT(std::fabs(sum_centre / sum_ref - 1.0), 0.4)
            << "voxel " << voxel << ": the cell's centre x a voxel kept the column (the test cannot tell)";
      }
      EXPECT_NEAR(ratio, 1.0,
                  k == 1   ? 0.28
                  : k == 2 ? 0.22
                           : 0.15)
          << "voxel " << voxel << ", supersample " << k << ": the columns' sum";
      EXPECT_LT(rms, k == 1 ? 0.30 : 0.25) << "voxel " << voxel << ", supersample " << k << ": the column RMS error";
    }
  }
}

}  // namespace
