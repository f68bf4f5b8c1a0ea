// density_block.cpp — choosing the batched kernel's instruction-set level (see density_block.h).
#include "cloudgen/density_block.h"

#if defined(CLOUDGEN_SIMD_X86)
#include <cpuid.h>
#endif

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "simd/levels.h"

namespace cg {

namespace {

using Entry = void (*)(const Model&, const vec3*, std::size_t, const Lod&, float*);

void scalar_points(const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out) {
  for (std::size_t i = 0; i < n; ++i) out[i] = density(m, points[i], lod);
}

Entry entry(SimdLevel level) {
  switch (level) {
#if defined(CLOUDGEN_SIMD_X86)
    case SimdLevel::Baseline:
      return simd_baseline::density_points;
    case SimdLevel::Avx2:
      return simd_avx2::density_points;
    case SimdLevel::Avx512:
      return simd_avx512::density_points;
#endif
    default:
      return scalar_points;
  }
}

#if defined(CLOUDGEN_SIMD_X86)
// CPUID leaf 1, ECX bit `bit` (F16C is bit 29, MOVBE bit 22): clang 14's
// __builtin_cpu_supports does not know "f16c" or "movbe", cpuid does.
bool cpuid1_ecx(int bit) {
  unsigned a = 0, b = 0, c = 0, d = 0;
  return __get_cpuid(1, &a, &b, &c, &d) && ((c >> bit) & 1u);
}
#endif

bool cpu_has(SimdLevel level) {
#if defined(CLOUDGEN_SIMD_X86)
  __builtin_cpu_init();
  switch (level) {
    case SimdLevel::Scalar:
      return true;
    case SimdLevel::Baseline:
      return __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt") && __builtin_cpu_supports("ssse3");
    case SimdLevel::Avx2:
      return cpu_has(SimdLevel::Baseline) && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
             __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") && cpuid1_ecx(29) /* F16C */ &&
             cpuid1_ecx(22) /* MOVBE */;
    case SimdLevel::Avx512:
      return cpu_has(SimdLevel::Avx2) && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
             __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512cd");
  }
  return false;
#else
  return level == SimdLevel::Scalar;
#endif
}

SimdLevel best_supported(SimdLevel at_most) {
  for (int l = int(at_most); l > 0; --l)
    if (cpu_has(SimdLevel(l))) return SimdLevel(l);
  return SimdLevel::Scalar;
}

SimdLevel choose_at_start() {
  const SimdLevel best = best_supported(SimdLevel::Avx512);
  const char* env = std::getenv("CLOUDGEN_SIMD");
  if (!env || !*env) return best;
  SimdLevel asked;
  if (!parse_simd_level(env, asked)) {
    std::fprintf(stderr, "cloudgen: CLOUDGEN_SIMD=%s is not scalar, baseline, avx2 or avx512; using %s\n", env,
                 simd_level_name(best));
    return best;
  }
  const SimdLevel used = best_supported(asked);
  if (used != asked)
    std::fprintf(stderr, "cloudgen: CLOUDGEN_SIMD=%s is not supported on this CPU; using %s\n", env,
                 simd_level_name(used));
  return used;
}

}  // namespace

const char* simd_level_name(SimdLevel level) {
  switch (level) {
    case SimdLevel::Scalar:
      return "scalar";
    case SimdLevel::Baseline:
      return "baseline";
    case SimdLevel::Avx2:
      return "avx2";
    case SimdLevel::Avx512:
      return "avx512";
  }
  return "?";
}

bool parse_simd_level(const char* name, SimdLevel& level) {
  for (int l = 0; l < kSimdLevelCount; ++l)
    if (std::strcmp(name, simd_level_name(SimdLevel(l))) == 0) {
      level = SimdLevel(l);
      return true;
    }
  return false;
}

bool simd_level_supported(SimdLevel level) { return cpu_has(level); }

SimdLevel simd_level() {
  static const SimdLevel level = choose_at_start();
  return level;
}

void density_block(const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out) {
  static const Entry e = entry(simd_level());
  e(m, points, n, lod, out);
}

void density_block(SimdLevel level, const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out) {
  entry(best_supported(level))(m, points, n, lod, out);
}

}  // namespace cg
