// field_key.cpp — a fingerprint of the density field a parameter set makes.
//
// density() is a pure function of the prepared Model (model.h), so the key
// hashes exactly what prepare() hands the kernel: every row of
// model_fields.h, in its order (box, shape, frequencies, the wrapped noise
// offsets, the 4th noise coordinate, the noise weights, the seed). Time
// reaches the field only through those offsets (wind × time) and w4
// (time × evolution), so a still cloud — no wind, no evolution — has one key
// at every time, and so do parameter sets that differ only where the kernel
// cannot tell.
//
// Two special cases, both explicit below:
//   - density 0 zeroes the field: one key for every such Model;
//   - shape_mode picks the profile: the exponent is hashed only in mode 0,
//     the curve only in mode 1 (each row's key_rule).
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
  // One Model field by its type; any other type is a compile error, so a new
  // field type must choose its bytes here.
  void add(float v) { f(v); }
  void add(std::int32_t v) { i(v); }
  void add(const vec3& v) { v3(v); }
  template <std::size_t N>
  void add(const float (&a)[N]) {
    for (float v : a) f(v);
  }
  template <class T>
  void add(const T&) = delete;
};

std::string hex(std::uint64_t v) {
  static const char* const digits = "0123456789abcdef";
  std::string out(16, '0');
  for (int k = 0; k < 16; ++k) out[k] = digits[(v >> (60 - 4 * k)) & 0xf];
  return out;
}

// When a field reaches the density (the key_rule column of model_fields.h).
enum class KeyRule { Always, ExponentShape, CurveShape };

bool reaches_field(KeyRule rule, const Model& m) {
  switch (rule) {
    case KeyRule::Always:
      return true;
    case KeyRule::ExponentShape:
      return m.shape_mode != 1;  // cg_profile uses the exponent unless mode is 1
    case KeyRule::CurveShape:
      return m.shape_mode == 1;
  }
  return true;
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
#define CG_MODEL_FIELD(type, name, key_rule) \
  if (reaches_field(KeyRule::key_rule, m)) h.add(m.name);
#define CG_MODEL_ARRAY(type, name, count, key_rule) CG_MODEL_FIELD(type, name, key_rule)
#include "cloudgen/model_fields.h"
#undef CG_MODEL_ARRAY
#undef CG_MODEL_FIELD
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
  if (o.has_ring()) h.i(0x72696e67), h.f(o.ring_inner), h.f(o.ring_outer);   // "ring"; a whole box keeps its key
  if (o.samples_per_axis() > 1) h.i(0x73757073), h.i(o.samples_per_axis());  // "sups"
  // "clip": a cell overhanging the box is sampled inside it, weighted by its share; since
  // 2026-11-27 point-sampled bakes too, so bakes cached before then are redone.
  h.i(0x636c6970);
  return field_key(m) + "-" + hex(h.h);
}

}  // namespace cg
