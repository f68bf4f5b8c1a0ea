// simd/levels.h — the entry point of each instruction-set object file (internal to the core).
// Each lives in its own namespace, compiled from kernel_block.h with its own -march.
#pragma once

#include <cstddef>

#include "cloudgen/model.h"

#define CG_SIMD_LEVEL_ENTRY(ns)                                                                       \
  namespace cg::ns {                                                                                  \
  void density_points(const Model& m, const vec3* points, std::size_t n, const Lod& lod, float* out); \
  }

#if defined(CLOUDGEN_SIMD_X86)
CG_SIMD_LEVEL_ENTRY(simd_baseline)
CG_SIMD_LEVEL_ENTRY(simd_avx2)
CG_SIMD_LEVEL_ENTRY(simd_avx512)
#endif
