// test_util.h — helpers shared by the native kernel tests: a seeded,
// platform-independent RNG and the sample-count scale (CLOUDGEN_TEST_SCALE).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cloudgen/grid.h"
#include "cloudgen/model.h"
#include "cloudgen/param_io.h"
#include "cloudgen/params.h"

namespace cgtest {

// SplitMix64: fixed seeds give the same sequence on every platform and
// standard library (std::uniform_real_distribution does not promise that).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) with 53 bits.
  double unit() { return double(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * unit(); }
  float uniformf(double lo, double hi) { return static_cast<float>(uniform(lo, hi)); }
  int integer(int lo, int hi) { return lo + int(next() % std::uint64_t(hi - lo + 1)); }

 private:
  std::uint64_t s_;
};

// CLOUDGEN_TEST_SCALE=sanitize shrinks the sample counts (the sanitized build
// is 3-10x slower); a number multiplies them.
inline double scale() {
  const char* s = std::getenv("CLOUDGEN_TEST_SCALE");
  if (!s || !*s) return 1.0;
  if (std::strcmp(s, "sanitize") == 0) return 0.1;
  const double v = std::atof(s);
  return v > 0.0 ? v : 1.0;
}
inline bool sanitize() {
  const char* s = std::getenv("CLOUDGEN_TEST_SCALE");
  return s && std::strcmp(s, "sanitize") == 0;
}
// `full` samples scaled, but never fewer than `floor_count`.
inline std::int64_t count(std::int64_t full, std::int64_t floor_count) {
  return std::max<std::int64_t>(floor_count, std::int64_t(double(full) * scale()));
}

inline std::string str(cg::vec3 p) {
  std::ostringstream o;
  o.precision(9);
  o << "(" << p[0] << ", " << p[1] << ", " << p[2] << ")";
  return o.str();
}

// Every parameter value that differs from its default, for failure messages.
inline std::string describe(const cg::Params& p) {
  const cg::Params d;
  std::ostringstream o;
  o.precision(9);
  o << "{";
  bool first = true;
  for (int i = 0; i < cg::PARAM_COUNT; ++i) {
    const cg::ParamDecl& decl = cg::kParams[i];
    for (int c = 0; c < cg::component_count(decl.kind); ++c) {
      const float v = p.get(cg::P(i), c);
      if (std::memcmp(&v, &d.values[cg::slot_of(cg::P(i)) + c], sizeof v) == 0) continue;
      o << (first ? "" : ", ") << decl.key;
      if (cg::component_count(decl.kind) > 1) o << "[" << c << "]";
      o << "=" << v;
      first = false;
    }
  }
  o << "}";
  return o.str();
}

// Noise switched off: N = 1/2 everywhere, so density = max(shape, 0) * Density.
inline void noise_off(cg::Params& p) {
  p.set(cg::WORLEY_INFLUENCE, 0.0f);
  p.set(cg::NOISE_INFLUENCE, 0.0f);
}

// A preset's parameters (a failure, and the defaults, when it is missing).
inline cg::Params preset(const char* name) {
  const cg::Preset* p = cg::find_preset(name);
  EXPECT_NE(p, nullptr) << "preset '" << name << "' missing";
  return p ? p->params : cg::Params();
}

// The bake as a dense array (x fastest), 0 where no tile was kept; voxel (x, y, z) is at
// dense_index(grid, x, y, z).
inline std::size_t dense_index(const cg::GridSpec& g, int x, int y, int z) {
  return (std::size_t(z) * std::size_t(g.n[1]) + std::size_t(y)) * std::size_t(g.n[0]) + std::size_t(x);
}
inline std::vector<float> to_dense(const cg::BakeResult& r) {
  const cg::GridSpec& g = r.grid;
  std::vector<float> out(std::size_t(g.voxel_count()), 0.0f);
  for (const cg::Tile& t : r.tiles)
    for (int k = 0; k < cg::kTile; ++k)
      for (int j = 0; j < cg::kTile; ++j)
        for (int i = 0; i < cg::kTile; ++i) {
          const int x = t.index[0] + i, y = t.index[1] + j, z = t.index[2] + k;
          if (x >= g.n[0] || y >= g.n[1] || z >= g.n[2]) continue;
          out[dense_index(g, x, y, z)] = t.values[(k * cg::kTile + j) * cg::kTile + i];
        }
  return out;
}

// What a point-sampled bake (supersample 1) holds at voxel (i, j, k), stated apart from the
// bake's code: the density at the voxel's centre; where the cell overhangs the model's box
// (the density is 0 outside it), the density at the centre of the cell's part inside the box
// times that part's share of the cell (docs/camera.md, "Box-filtered bakes").
inline float point_bake_value(const cg::Model& m, const cg::GridSpec& g, int i, int j, int k, const cg::Lod& lod) {
  const cg::vec3 c = g.centre(i, j, k);
  cg::vec3 p = c;
  float share = 1.0f;
  for (int a = 0; a < 3; ++a) {
    const float half = 0.5f * m.box[a];
    const float lo = c[a] - 0.5f * g.voxel, hi = c[a] + 0.5f * g.voxel;
    if (lo >= -half && hi <= half) continue;
    const float in_lo = std::max(lo, -half), in_span = std::max(std::min(hi, half) - in_lo, 0.0f);
    p[a] = in_lo + 0.5f * in_span;
    share *= in_span / g.voxel;
  }
  const float d = cg::density(m, p, lod);
  return share < 1.0f ? d * share : d;
}

}  // namespace cgtest
