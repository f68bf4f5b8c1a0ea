// field_key.cpp — a fingerprint of the density field a parameter set makes.
//
// density() is a pure function of the prepared Model (model.h), so the key
// hashes exactly what prepare() hands the kernel: box, shape, frequencies,
// the wrapped noise offsets and the 4th noise coordinate. Time reaches the
// field only through those offsets (wind × time) and w4 (time × evolution),
// so a still cloud — no wind, no evolution — has one key at every time, and
// so do parameter sets that differ only where the kernel cannot tell.
#include "cloudgen/field_key.h"

#include <cstdint>
#include <cstring>

namespace cg {

namespace {

struct Fnv1a {
  std::uint64_t h = 14695981039346656037ull;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  }
  void f(float v) {
    if (v == 0.0f) v = 0.0f;  // -0 and +0 make the same field
    std::uint32_t u;
    std::memcpy(&u, &v, sizeof u);
    bytes(&u, sizeof u);
  }
  void i(std::int32_t v) { bytes(&v, sizeof v); }
  void v3(const vec3& v) { f(v[0]), f(v[1]), f(v[2]); }
};

std::string hex(std::uint64_t v) {
  static const char* const digits = "0123456789abcdef";
  std::string out(16, '0');
  for (int k = 0; k < 16; ++k) out[k] = digits[(v >> (60 - 4 * k)) & 0xf];
  return out;
}

}  // namespace

std::string field_key(const Model& m) {
  Fnv1a h;
  h.i(kFieldKeyVersion);
  if (!(m.density > 0.0f)) {
    // Density 0 (eq. 3.4's factor) zeroes the field everywhere: every such
    // parameter set has one key, whatever the shape and noise.
    h.i(0x7a65726f);
    return hex(h.h);
  }
  h.v3(m.box);
  h.f(m.cloud_scale);
  h.i(m.shape_mode);
  if (m.shape_mode == 1) {
    for (float c : m.curve) h.f(c);
  } else {
    h.f(m.shape_exponent);
  }
  for (float v : {m.distortion, m.density, m.worley_frequency, m.perlin_frequency}) h.f(v);
  h.v3(m.worley_offset);
  h.v3(m.perlin_offset);
  h.f(m.w4);
  for (float v : {m.worley_influence, m.worley_clump, m.wave, m.noise_influence, m.noise_detail, m.noise_whisp})
    h.f(v);
  h.i(m.seed);
  return hex(h.h);
}

std::string field_key(const Params& p) { return field_key(prepare(p)); }

std::string bake_key(const Model& m, const BakeOptions& o, bool half) {
  const GridSpec g = bake_grid(m, o);
  Fnv1a h;
  for (int a = 0; a < 3; ++a) h.i(g.n[a]);
  h.f(g.voxel);
  h.i(o.lod);
  h.i(half);
  h.i(o.use_region);
  h.f(o.tolerance);
  if (o.brick_count > 1) h.i(o.brick_index), h.i(o.brick_count);  // a whole bake keeps its key
  if (o.use_region) {
    for (const Plane& p : o.region.planes) h.v3(p.n), h.f(p.d);
    for (int l = 0; l < o.region.light_count; ++l) h.v3(o.region.lights[l]);
  }
  return field_key(m) + "-" + hex(h.h);
}

}  // namespace cg
