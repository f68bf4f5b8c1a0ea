// cloudgen/density_block.h — the batched density kernel and its instruction-set levels.
//
// density_block() evaluates cg::density (model.h) at many points at once: the
// shape decides per point (outside the box or provably empty: 0, no noise),
// then the noise of the remaining points is computed lanes-across-points from
// the same shared source (shared/*.h), octave by octave. The result equals
// cg::density bit for bit at every level (tests/native/test_simd.cpp).
//
// Levels: one object file per instruction set (native/src/simd/), chosen once
// at start-up from the CPU's features; CLOUDGEN_SIMD=scalar|baseline|avx2|avx512
// forces one (lowered to the best the CPU supports, with a note on stderr).
#pragma once

#include <cstddef>

#include "cloudgen/model.h"

namespace cg {

enum class SimdLevel : int {
  Scalar = 0,    // cg::density point by point (any CPU, any architecture)
  Baseline = 1,  // x86-64-v2 (SSE4.2): 4 lanes
  Avx2 = 2,      // x86-64-v3 (AVX2, FMA unused: -ffp-contract=off): 8 lanes
  Avx512 = 3,    // x86-64-v4 (AVX-512 F/BW/DQ/VL): 16 lanes
};
inline constexpr int kSimdLevelCount = 4;

const char* simd_level_name(SimdLevel level);
// Parses "scalar", "baseline", "avx2", "avx512"; false when unknown.
bool parse_simd_level(const char* name, SimdLevel& level);
// Compiled into this build and runnable on this CPU.
bool simd_level_supported(SimdLevel level);
// The level density_block() uses: CLOUDGEN_SIMD when set (and supported), else the best supported.
SimdLevel simd_level();

// out[i] = density(m, points[i], lod) for i in [0, n), at the active level.
void density_block(const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out);
// The same at a given level (tests, benchmarks); an unsupported level runs at the best supported one below it.
void density_block(SimdLevel level, const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out);

}  // namespace cg
