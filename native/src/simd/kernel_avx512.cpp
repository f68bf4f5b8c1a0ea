// kernel_avx512.cpp — the batched density kernel for one instruction set (see kernel_block.h and CMakeLists.txt).
#define CG_SIMD_NS simd_avx512
#include "kernel_block.h"
