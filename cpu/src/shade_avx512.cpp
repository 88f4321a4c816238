// The batched path step for AVX-512: 16 lanes (shade_kernels.inc). The target implies
// FMA; -ffp-contract=off (top-level CMakeLists.txt) keeps every a * b + c that the scalar
// path step does not fuse two roundings: FMAs only where it calls pb::fmadd (simd8.h's madd).
#define PB_SIMD_NS avx512
#define PB_SIMD_LANES 16
#define PB_SIMD_TARGET "avx512f,avx512bw,avx512dq,avx512vl,popcnt"
#define PB_SIMD_ISA Avx512
#define PB_SIMD_KERNELS avx512_kernels
#include "shade_kernels.inc"
