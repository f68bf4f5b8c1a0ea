// test_simd.cpp — the batched kernel (cg::density_block) equals the scalar kernel
// (cg::density) bit for bit, at every instruction-set level this CPU supports.
//
// Tolerance: none. Two floats are equal when their 32 bits are (std::memcmp).
// Cases (about 10^6 points in all at CLOUDGEN_TEST_SCALE=1): the defaults, every
// preset, random parameter sets over the declared ranges, every parameter at its
// declared min and max, and the field far from the origin (points and offsets up
// to 1e6 and beyond), each with and without a level-of-detail limit. A failure
// prints the level, the point, both values and the parameters.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cloudgen/density_block.h"
#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/param_io.h"
#include "cloudgen/params.h"
#include "test_util.h"

namespace {

using cg::vec3;
using cgtest::Rng;

// Half the points uniformly in the box (most of them need noise), a quarter just
// around it, the rest anywhere up to |x| = 2e6 on a log scale.
vec3 point_for(const cg::Model& m, Rng& rng, std::int64_t i) {
  vec3 p;
  const int kind = int(i % 8);
  for (int a = 0; a < 3; ++a) {
    const double half = 0.5 * double(m.box[a]);
    if (kind < 4)
      p[a] = rng.uniformf(-half, half);
    else if (kind < 6)
      p[a] = rng.uniformf(-1.5 * half, 1.5 * half);
    else
      p[a] = float(std::pow(10.0, rng.uniform(-3, 6.3)) * (rng.unit() < 0.5 ? -1 : 1));
  }
  return p;
}

std::string hex(float v) {
  std::uint32_t b;
  std::memcpy(&b, &v, sizeof b);
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g (0x%08x)", double(v), unsigned(b));
  return buf;
}

struct Checker {
  std::int64_t points = 0, nonzero = 0, failures = 0;

  // Compares every supported level with the scalar kernel on n points of `params`: scattered points, and
  // clusters of 128 (like a tile or a row: the kernel's Worley table path) in cubes of 0.001-3 Worley cells.
  void run(const std::string& name, const cg::Params& params, std::int64_t n, std::uint64_t seed) {
    const cg::Model m = cg::prepare(params);
    Rng rng(seed);
    std::vector<vec3> pts(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) pts[std::size_t(i)] = point_for(m, rng, i);
    compare(name + " (scattered)", params, m, pts, seed);
    for (std::int64_t c = 0; c < n; c += 128) {
      const vec3 centre = point_for(m, rng, c % 4);
      const float size = float(std::pow(10.0, rng.uniform(-3, 0.5))) / m.worley_frequency;  // 0.001-3 cells
      for (std::int64_t i = c; i < std::min(n, c + 128); ++i)
        for (int a = 0; a < 3; ++a) pts[std::size_t(i)][a] = centre[a] + rng.uniformf(-0.5, 0.5) * size;
    }
    compare(name + " (clustered)", params, m, pts, seed);
  }

  void compare(const std::string& name, const cg::Params& params, const cg::Model& m, const std::vector<vec3>& pts,
               std::uint64_t seed) {
    const auto n = std::int64_t(pts.size());
    for (int with_lod = 0; with_lod < 2; ++with_lod) {
      const cg::Lod lod = with_lod ? cg::lod_for_footprint(m, 0.01f * m.box[0] * float(1 + seed % 7)) : cg::kNoLod;
      std::vector<float> want(pts.size());
      for (std::size_t i = 0; i < pts.size(); ++i) want[i] = cg::density(m, pts[i], lod);
      for (std::size_t i = 0; i < pts.size(); ++i) nonzero += want[i] != 0.0f;
      points += n;
      for (int l = 1; l < cg::kSimdLevelCount; ++l) {
        const cg::SimdLevel level = cg::SimdLevel(l);
        if (!cg::simd_level_supported(level)) continue;
        std::vector<float> got(pts.size(), -1.0f);
        cg::density_block(level, m, pts.data(), pts.size(), lod, got.data());
        for (std::size_t i = 0; i < pts.size(); ++i) {
          if (std::memcmp(&got[i], &want[i], sizeof(float)) == 0) continue;
          if (++failures <= 5)
            ADD_FAILURE() << "level " << cg::simd_level_name(level) << ", case " << name << ", point "
                          << cgtest::str(pts[i]) << ", lod (" << lod.worley_octaves << ", " << lod.perlin_octaves
                          << "): batched " << hex(got[i]) << " != scalar " << hex(want[i]) << "\n  params "
                          << cgtest::describe(params);
        }
      }
    }
  }
};

float uniform_value(Rng& rng, const cg::ParamDecl& d) {
  float v = rng.uniformf(d.min, d.max);
  if (d.kind == cg::Kind::Int) v = std::round(v);
  return v;
}

void set_all(cg::Params& p, cg::P id, float v) {
  for (int c = 0; c < cg::component_count(cg::kParams[id].kind); ++c) p.set_unchecked(id, c, v);
}

TEST(Simd, LevelsAndNames) {
  EXPECT_TRUE(cg::simd_level_supported(cg::SimdLevel::Scalar));
  for (int l = 0; l < cg::kSimdLevelCount; ++l) {
    cg::SimdLevel parsed;
    ASSERT_TRUE(cg::parse_simd_level(cg::simd_level_name(cg::SimdLevel(l)), parsed));
    EXPECT_EQ(int(parsed), l);
  }
  cg::SimdLevel unused;
  EXPECT_FALSE(cg::parse_simd_level("sse9", unused));
  EXPECT_TRUE(cg::simd_level_supported(cg::simd_level()));
  // CLOUDGEN_SIMD (ctest runs this binary once per level) is obeyed when the CPU supports the level.
  cg::SimdLevel forced;
  const char* env = std::getenv("CLOUDGEN_SIMD");
  if (env && cg::parse_simd_level(env, forced) && cg::simd_level_supported(forced)) {
    EXPECT_EQ(cg::simd_level(), forced) << "CLOUDGEN_SIMD=" << env;
  }
  std::printf("active level: %s; supported:", cg::simd_level_name(cg::simd_level()));
  for (int l = 0; l < cg::kSimdLevelCount; ++l)
    if (cg::simd_level_supported(cg::SimdLevel(l))) std::printf(" %s", cg::simd_level_name(cg::SimdLevel(l)));
  std::printf("\n");
}

TEST(Simd, DefaultsAndPresetsBitwise) {
  Checker c;
  c.run("defaults", cg::Params(), cgtest::count(200000, 20000), 1);
  std::uint64_t seed = 100;
  for (const cg::Preset& p : cg::presets()) c.run("preset " + p.name, p.params, cgtest::count(30000, 3000), ++seed);
  std::printf("%lld points, %lld non-zero, %lld mismatches\n", (long long)c.points, (long long)c.nonzero,
              (long long)c.failures);
  EXPECT_EQ(c.failures, 0);
  EXPECT_GT(c.nonzero, c.points / 20);
}

TEST(Simd, RandomParametersBitwise) {
  Checker c;
  Rng rng(0x51D);
  const int sets = int(cgtest::count(200, 20));
  for (int s = 0; s < sets; ++s) {
    cg::Params p;
    for (int i = 0; i < cg::PARAM_COUNT; ++i) {
      const cg::ParamDecl& d = cg::kParams[i];
      if (i == cg::BOX_SIZE) {
        for (int a = 0; a < 3; ++a) p.set_unchecked(cg::P(i), a, float(std::pow(10.0, rng.uniform(-2, 3))));
        continue;
      }
      for (int comp = 0; comp < cg::component_count(d.kind); ++comp)
        p.set_unchecked(cg::P(i), comp, uniform_value(rng, d));
    }
    // Switch parts off sometimes: the uniform branches of Cloud Noise.
    if (s % 5 == 1) p.set_unchecked(cg::WAVE, 0, 0.0f);
    if (s % 5 == 2) p.set_unchecked(cg::WAVE, 0, 1.0f);
    if (s % 7 == 3) p.set_unchecked(cg::NOISE_INFLUENCE, 0, 0.0f);
    if (s % 7 == 4) p.set_unchecked(cg::WORLEY_INFLUENCE, 0, 0.0f);
    c.run("random set " + std::to_string(s), p, cgtest::count(1500, 300), 1000 + std::uint64_t(s));
  }
  std::printf("%lld points, %lld non-zero, %lld mismatches\n", (long long)c.points, (long long)c.nonzero,
              (long long)c.failures);
  EXPECT_EQ(c.failures, 0);
}

TEST(Simd, ExtremesBitwise) {
  Checker c;
  std::uint64_t seed = 5000;
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const cg::ParamDecl& d = cg::kParams[i];
    for (const float v : {d.min, d.max}) {
      cg::Params p;
      set_all(p, cg::P(i), v);
      c.run(std::string(d.key) + "=" + std::to_string(v), p, cgtest::count(2000, 400), ++seed);
    }
  }
  cg::Params lo, hi;
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    set_all(lo, cg::P(i), cg::kParams[i].min);
    set_all(hi, cg::P(i), cg::kParams[i].max);
  }
  c.run("every parameter at its min", lo, cgtest::count(5000, 500), ++seed);
  c.run("every parameter at its max", hi, cgtest::count(5000, 500), ++seed);
  std::printf("%lld points, %lld non-zero, %lld mismatches\n", (long long)c.points, (long long)c.nonzero,
              (long long)c.failures);
  EXPECT_EQ(c.failures, 0);
}

TEST(Simd, FarFromOriginBitwise) {
  Checker c;
  std::uint64_t seed = 9000;
  // A box 2e6 wide (beyond the declared 1e5: the kernel's safe domain) puts points at +-1e6 inside the cloud.
  for (const float box : {1.0e5f, 2.0e6f}) {
    cg::Params p;
    set_all(p, cg::BOX_SIZE, box);
    c.run("box " + std::to_string(box), p, cgtest::count(30000, 3000), ++seed);
    for (const float where : {1.0e6f, -1.0e7f}) {
      cg::Params q = p;
      set_all(q, cg::OBJECT_LOCATION, where);
      q.set_unchecked(cg::STATIONARY, 0, 0.0f);
      q.set_unchecked(cg::TIME, 0, 1.0e6f);
      q.set_unchecked(cg::WIND_STRENGTH, 0, 100.0f);
      c.run("box " + std::to_string(box) + " far offsets " + std::to_string(where), q, cgtest::count(20000, 2000),
            ++seed);
    }
  }
  std::printf("%lld points, %lld non-zero, %lld mismatches\n", (long long)c.points, (long long)c.nonzero,
              (long long)c.failures);
  EXPECT_EQ(c.failures, 0);
}

// Regular 8^3 blocks (a bake tile: 4 chunks of 8 x 8 x 2 points) and rows of 256 points (a preview row),
// with a gradient-noise cell 0.05-40 spacings wide: every octave's cells span from one (the uniform
// table reads) through several (the gathered table) to too many (the per-lane path), at random origins
// in and around the box, for the defaults and every preset.
TEST(Simd, GridBlocksBitwise) {
  Checker c;
  Rng rng(0xB10C);
  std::vector<std::pair<std::string, cg::Params>> sets = {{"defaults", cg::Params()}};
  for (const cg::Preset& p : cg::presets()) sets.emplace_back("preset " + p.name, p.params);
  const int blocks = int(cgtest::count(24, 4));
  for (const auto& [name, params] : sets) {
    const cg::Model m = cg::prepare(params);
    std::vector<vec3> pts;
    for (int b = 0; b < blocks; ++b) {
      const float spacing =
          float(std::pow(10.0, rng.uniform(std::log10(1.0 / 40), std::log10(20.0)))) / m.perlin_frequency;
      const vec3 origin = point_for(m, rng, b % 6);
      if (b % 2 == 0) {
        for (int k = 0; k < 8; ++k)
          for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i)
              pts.push_back(
                  vec3(origin[0] + float(i) * spacing, origin[1] + float(j) * spacing, origin[2] + float(k) * spacing));
      } else {
        for (int i = 0; i < 256; ++i) pts.push_back(vec3(origin[0] + float(i) * spacing, origin[1], origin[2]));
      }
    }
    c.compare(name + " (blocks and rows)", params, m, pts, 77);
  }
  std::printf("%lld points, %lld non-zero, %lld mismatches\n", (long long)c.points, (long long)c.nonzero,
              (long long)c.failures);
  EXPECT_EQ(c.failures, 0);
  EXPECT_GT(c.nonzero, c.points / 20);
}

// The bake (8^3 tiles through density_block at the active level) equals cg::density at every voxel centre
// (at the centre of the part inside the box, times its share, where a cell overhangs the box).
TEST(Simd, BakeEqualsScalarDensityBitwise) {
  std::int64_t failures = 0, voxels = 0;
  for (const char* name : {"cumulus", "cirrus", "stratocumulus"}) {
    const cg::Preset* preset = cg::find_preset(name);
    const cg::Params params = preset ? preset->params : cg::Params();
    const cg::Model m = cg::prepare(params);
    cg::BakeOptions o;
    o.resolution = int(cgtest::count(40, 24));
    o.lod = true;
    o.threads = 2;
    const cg::BakeResult r = cg::bake(m, o);
    const cg::Lod lod = cg::lod_for_footprint(m, r.grid.voxel);
    for (const cg::Tile& t : r.tiles)
      for (int k = 0; k < cg::kTile; ++k)
        for (int j = 0; j < cg::kTile; ++j)
          for (int i = 0; i < cg::kTile; ++i) {
            const int x = t.index[0] + i, y = t.index[1] + j, z = t.index[2] + k;
            if (x >= r.grid.n[0] || y >= r.grid.n[1] || z >= r.grid.n[2]) continue;
            const float got = t.values[std::size_t((k * cg::kTile + j) * cg::kTile + i)];
            const float want = cgtest::point_bake_value(m, r.grid, x, y, z, lod);
            ++voxels;
            if (std::memcmp(&got, &want, sizeof got) != 0 && ++failures <= 5)
              ADD_FAILURE() << name << " voxel (" << x << ", " << y << ", " << z << "): bake " << hex(got)
                            << " != density " << hex(want) << " at level " << cg::simd_level_name(cg::simd_level());
          }
  }
  std::printf("%lld voxels of kept tiles compared\n", (long long)voxels);
  EXPECT_GT(voxels, 0);
  EXPECT_EQ(failures, 0);
}

// Every call size from 0 to 300 (chunk boundaries, padding lanes), the active level via the plain entry.
TEST(Simd, EveryCallSize) {
  const cg::Model m = cg::prepare(cg::Params());
  Rng rng(77);
  std::vector<vec3> pts(300);
  for (std::size_t i = 0; i < pts.size(); ++i) pts[i] = point_for(m, rng, std::int64_t(i % 4));
  std::int64_t failures = 0;
  for (std::size_t n = 0; n <= pts.size(); n += (n < 40 ? 1 : 13)) {
    std::vector<float> got(n + 1, -1.0f);
    cg::density_block(m, pts.data(), n, cg::kNoLod, got.data());
    EXPECT_EQ(got[n], -1.0f) << "wrote past the end at n = " << n;
    for (std::size_t i = 0; i < n; ++i) {
      const float want = cg::density(m, pts[i], cg::kNoLod);
      if (std::memcmp(&got[i], &want, sizeof want) != 0 && ++failures <= 5)
        ADD_FAILURE() << "n = " << n << ", point " << cgtest::str(pts[i]) << ": batched " << hex(got[i])
                      << " != scalar " << hex(want);
    }
  }
  EXPECT_EQ(failures, 0);
}

}  // namespace
