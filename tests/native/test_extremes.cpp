// test_extremes.cpp — the kernel called directly (cg::prepare + cg::density,
// parameters written with Params::set_unchecked) at and far beyond the declared
// limits, and the field far from the origin.
//
// Property (docs/model.md §7, model.h): for every finite parameter value and every
// finite point, density is finite and >= 0 and N is in [0, 1].
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/parallel.h"
#include "cloudgen/params.h"
#include "test_util.h"

namespace {

using cg::vec3;
using cgtest::Rng;

// The i-th test point for a model: half uniformly inside the box, a quarter within
// three box sizes, the rest anywhere up to |x| = 2e6 on a log scale, with points
// exactly at +-1e6 and at box corners among them.
vec3 test_point(const cg::Model& m, Rng& rng, std::int64_t i) {
  vec3 p;
  const int kind = int(i % 8);
  for (int a = 0; a < 3; ++a) {
    const double half = 0.5 * double(m.box[a]);
    double v;
    if (kind < 4) {
      v = rng.uniform(-half, half);
    } else if (kind < 6) {
      v = rng.uniform(-3 * half, 3 * half);
    } else if (kind == 6) {
      v = std::pow(10.0, rng.uniform(-3, 6.3)) * (rng.unit() < 0.5 ? -1 : 1);
    } else {
      const double choices[] = {1e6, -1e6, half, -half, 0.0};
      v = choices[rng.integer(0, 4)];
    }
    p[a] = float(v);
  }
  return p;
}

struct Outcome {
  std::int64_t evaluated = 0, positive = 0;
  std::string failure;  // first failure, empty if none
};

// Evaluates density (and N, the shape, a small slice) at `n` points on two threads.
Outcome run_case(const cg::Params& params, std::int64_t n, std::uint64_t seed) {
  Outcome out;
  const cg::Model m = cg::prepare(params);
  std::mutex mutex;
  std::atomic<std::int64_t> positive{0};
  const std::int64_t chunk = 4096, chunks = (n + chunk - 1) / chunk;
  auto fail = [&](const std::string& what, vec3 p, float v) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!out.failure.empty()) return;
    std::ostringstream o;
    o.precision(9);
    o << what << " = " << v << " at " << cgtest::str(p) << " with " << cgtest::describe(params);
    out.failure = o.str();
  };
  cg::parallel_for(chunks, 2, [&](std::int64_t c, int) {
    Rng rng(seed * 1000003u + std::uint64_t(c));
    std::int64_t pos = 0;
    for (std::int64_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i) {
      const vec3 p = test_point(m, rng, i);
      const float d = cg::density(m, p);
      if (!std::isfinite(d) || d < 0.0f) return fail("density", p, d);
      pos += d > 0.0f;
      if (i % 16 == 0) {
        const float nv = cg::noise_at(m, p);
        if (!(nv >= 0.0f && nv <= 1.0f)) return fail("noise N", p, nv);
        const float s = cg::shape_at(m, p);
        if (!std::isfinite(s)) return fail("shape", p, s);
      }
    }
    positive += pos;
  });
  out.evaluated = n;
  out.positive = positive;
  if (out.failure.empty()) {
    cg::SliceSpec spec;
    spec.width = spec.height = 12;
    spec.threads = 1;
    for (int axis = 0; axis < 3 && out.failure.empty(); ++axis) {
      spec.axis = axis;
      const std::vector<float> img = cg::slice(m, spec);
      for (float v : img)
        if (!std::isfinite(v) || v < 0.0f) {
          fail("slice value", cg::slice_point(m, spec, 0, 0), v);
          break;
        }
    }
    const float b = cg::shape_upper_bound(m, vec3(-1, -1, -1), vec3(1, 1, 1));
    if (std::isnan(b)) fail("shape_upper_bound", vec3(), b);
  }
  return out;
}

std::int64_t points_per_case() { return cgtest::count(100000, 10000); }
// The values beyond the spec's list (+-FLT_MAX) get a tenth of the points.
std::int64_t points_for(std::size_t value_index) {
  return value_index < 6 ? points_per_case() : std::max<std::int64_t>(10000, points_per_case() / 10);
}

struct Slot {
  cg::P p;
  int component;
};
std::vector<Slot> all_slots() {
  std::vector<Slot> s;
  for (int i = 0; i < cg::PARAM_COUNT; ++i)
    for (int c = 0; c < cg::component_count(cg::kParams[i].kind); ++c) s.push_back({cg::P(i), c});
  return s;
}

// Declared minimum, maximum, 0, 10x maximum, -maximum, -1e30, and the largest finite floats.
std::vector<float> extreme_values(const cg::ParamDecl& d) {
  return {d.min, d.max, 0.0f, 10.0f * d.max, -d.max, -1e30f, FLT_MAX, -FLT_MAX};
}

TEST(Extremes, EveryParameterInTurn) {
  // Tolerance: none — finite and >= 0 (N in [0, 1]) at every point, for every slot
  // (each vector and curve component) at each extreme value, the others at defaults.
  const std::int64_t n = points_per_case();
  std::uint64_t seed = 1;
  std::int64_t cases = 0;
  for (const Slot& s : all_slots()) {
    const std::vector<float> values = extreme_values(cg::kParams[s.p]);
    for (std::size_t k = 0; k < values.size(); ++k) {
      cg::Params p;
      p.set_unchecked(s.p, s.component, values[k]);
      const Outcome o = run_case(p, points_for(k), seed++);
      ++cases;
      ASSERT_TRUE(o.failure.empty()) << o.failure;
    }
  }
  std::cout << "[ figures  ] " << cases << " single-parameter cases x " << n << " points (+-FLT_MAX: " << points_for(7)
            << ")\n";
}

TEST(Extremes, AllParametersAtOnce) {
  // All slots at the same extreme (all min, all max, all 10x max, all 0, all -max,
  // all -1e30, all +-FLT_MAX), and min/max alternating by slot.
  const std::int64_t n = points_per_case();
  const std::vector<Slot> slots = all_slots();
  for (int which = 0; which < 10; ++which) {
    cg::Params p;
    for (std::size_t k = 0; k < slots.size(); ++k) {
      const cg::ParamDecl& d = cg::kParams[slots[k].p];
      const std::vector<float> v = extreme_values(d);
      const float value = which < 8 ? v[std::size_t(which)] : ((k + std::size_t(which)) % 2 ? d.min : d.max);
      p.set_unchecked(slots[k].p, slots[k].component, value);
    }
    const Outcome o = run_case(p, n, 1000 + std::uint64_t(which));
    ASSERT_TRUE(o.failure.empty()) << "combination " << which << ": " << o.failure;
  }
}

TEST(Extremes, LongWindDriftInsideTheLimits) {
  // The largest drift the declared limits allow (time 1e6 s, strength 100) along a
  // short direction, with the object far away and Stationary 0.
  const std::int64_t n = cgtest::count(50000, 10000);
  for (float dir : {1.0f, 1e-3f, -1e-6f}) {
    cg::Params p;
    p.set(cg::TIME, 1e6f);
    p.set(cg::WIND_STRENGTH, 100.0f);
    const float d[3] = {dir, 0, dir};
    p.set(cg::WIND_DIRECTION, d, 3);
    p.set(cg::STATIONARY, 0.0f);
    const float l[3] = {1e7f, -1e7f, 5e6f};
    p.set(cg::OBJECT_LOCATION, l, 3);
    const Outcome o = run_case(p, n, 77);
    EXPECT_TRUE(o.failure.empty()) << o.failure;
  }
}

// Regression: cg_noise_offset once divided strength * time (each clamped to 1e9)
// by the direction's length; for a direction of length ~1e-22 (its square a float
// denormal) the quotient overflowed to Inf and cg_wrap(-Inf) gave NaN. The
// direction is now normalised after scaling by its largest component.
TEST(Extremes, TinyWindDirectionWithHugeDrift) {
  cg::Params p;
  p.set_unchecked(cg::WIND_DIRECTION, 0, 1e-22f);
  p.set_unchecked(cg::WIND_DIRECTION, 1, 0.0f);
  p.set_unchecked(cg::WIND_DIRECTION, 2, 0.0f);
  p.set_unchecked(cg::WIND_STRENGTH, 0, 1e9f);
  p.set_unchecked(cg::TIME, 0, 1e9f);
  const cg::Model m = cg::prepare(p);
  for (int a = 0; a < 3; ++a) {
    EXPECT_TRUE(std::isfinite(m.worley_offset[a])) << "worley_offset[" << a << "] = " << m.worley_offset[a];
    EXPECT_TRUE(std::isfinite(m.perlin_offset[a])) << "perlin_offset[" << a << "] = " << m.perlin_offset[a];
  }
  const Outcome o = run_case(p, 10000, 5);
  EXPECT_TRUE(o.failure.empty()) << o.failure;
}

// ------------------------------------------------------- far from the origin ---

struct FieldStats {
  double mean_d = 0, sd_d = 0, mean_n = 0, sd_n = 0;
  double distinct = 0;  // fraction of distinct N values
};

FieldStats field_stats(const cg::Params& params, int n) {
  const cg::Model m = cg::prepare(params);
  std::vector<float> d(std::size_t(n) * n * n), nv(d.size());
  cg::parallel_for(n, 2, [&](std::int64_t k, int) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const vec3 g((i + 0.5f) / float(n), (j + 0.5f) / float(n), (float(k) + 0.5f) / float(n));
        const vec3 p((g[0] - 0.5f) * m.box[0], (g[1] - 0.5f) * m.box[1], (g[2] - 0.5f) * m.box[2]);
        const std::size_t idx = (std::size_t(k) * n + j) * n + i;
        // N once per sample; the density from it through the kernel's own eq. 3.4
        // (equal to cg::density inside the box, also where the shape proves it empty).
        nv[idx] = cg::noise_at(m, p);
        const vec3 gp = cg::generated(m, p);
        d[idx] = cg::cg_cloud_main(cg::shape_at(m, p), nv[idx], cg::distortion_at_generated(m, gp), m.density,
                                   cg::edge_width_at_generated(m, gp));
      }
  });
  FieldStats s;
  double sd = 0, sd2 = 0, sn = 0, sn2 = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    sd += double(d[i]);
    sd2 += double(d[i]) * double(d[i]);
    sn += double(nv[i]);
    sn2 += double(nv[i]) * double(nv[i]);
  }
  const double c = double(d.size());
  s.mean_d = sd / c;
  s.sd_d = std::sqrt(std::max(0.0, sd2 / c - s.mean_d * s.mean_d));
  s.mean_n = sn / c;
  s.sd_n = std::sqrt(std::max(0.0, sn2 / c - s.mean_n * s.mean_n));
  std::sort(nv.begin(), nv.end());
  s.distinct = double(std::unique(nv.begin(), nv.end()) - nv.begin()) / c;
  return s;
}

TEST(FarFromOrigin, FieldStatisticsMatchTheOrigin) {
  // Stationary 0, so the object location enters the noise (wrapped modulo the lattice
  // period before it meets the local coordinate). Over 64^3 samples in the box, the
  // mean and standard deviation of density and of N at object offsets 1e3 ... 1e6
  // (along x and along the diagonal) are within 5 % of those at the origin, the
  // fraction of distinct N values is at least 0.9x the origin's, and std > 0.5x.
  // The box (8 x 8 x 6, the noise at Overall Scale 1: 20 x 20 x 15 Worley cells) is
  // large enough that the statistics of one region are those of any other.
  const int n = 64;
  cg::Params base = cg::Params();
  base.set(cg::STATIONARY, 0.0f);
  const float box[3] = {8, 8, 6};
  base.set(cg::BOX_SIZE, box, 3);
  const FieldStats origin = field_stats(base, n);
  std::cout << "[ figures  ] origin: density mean " << origin.mean_d << " sd " << origin.sd_d << ", N mean "
            << origin.mean_n << " sd " << origin.sd_n << ", distinct N " << origin.distinct << "\n";
  for (double offset : {1e3, 1e4, 1e5, 1e6}) {
    for (bool diagonal : {false, true}) {
      cg::Params p = base;
      const float c = float(diagonal ? offset / std::sqrt(3.0) : offset);
      const float loc[3] = {c, diagonal ? c : 0.0f, diagonal ? c : 0.0f};
      p.set(cg::OBJECT_LOCATION, loc, 3);
      const FieldStats s = field_stats(p, n);
      std::cout << "[ figures  ] offset " << offset << (diagonal ? " diagonal" : " along x") << ": density mean "
                << s.mean_d << " (" << (s.mean_d / origin.mean_d - 1) * 100 << " %) sd " << s.sd_d << " ("
                << (s.sd_d / origin.sd_d - 1) * 100 << " %), N mean " << s.mean_n << " sd " << s.sd_n << ", distinct N "
                << s.distinct << "\n";
      const std::string where = "offset " + std::to_string(offset) + (diagonal ? " diagonal" : " along x");
      EXPECT_NEAR(s.mean_d, origin.mean_d, 0.05 * origin.mean_d) << where;
      EXPECT_NEAR(s.sd_d, origin.sd_d, 0.05 * origin.sd_d) << where;
      EXPECT_NEAR(s.mean_n, origin.mean_n, 0.05 * origin.mean_n) << where;
      EXPECT_NEAR(s.sd_n, origin.sd_n, 0.05 * origin.sd_n) << where;
      EXPECT_GT(s.sd_n, 0.5 * origin.sd_n) << where;
      EXPECT_GE(s.distinct, 0.9 * origin.distinct) << where;
    }
  }
}

}  // namespace
