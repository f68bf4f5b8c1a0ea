// kernel_baseline.cpp — the batched density kernel for one instruction set (see kernel_block.h and CMakeLists.txt).
#define CG_SIMD_NS simd_baseline
#include "kernel_block.h"
