// The batched path step for AVX2: 8 lanes (shade_kernels.inc).
#define PB_SIMD_NS avx2
#define PB_SIMD_LANES 8
#define PB_SIMD_TARGET "avx2,fma,popcnt"
#define PB_SIMD_ISA Avx2
#define PB_SIMD_KERNELS avx2_kernels
#include "shade_kernels.inc"
