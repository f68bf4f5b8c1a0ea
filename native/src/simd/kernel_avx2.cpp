// kernel_avx2.cpp — the batched density kernel for one instruction set (see kernel_block.h and CMakeLists.txt).
#define CG_SIMD_NS simd_avx2
#include "kernel_block.h"
