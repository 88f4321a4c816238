#pragma once
// The batched path step (shade_x8.h) compiled for AVX2 whatever the build's baseline, in
// namespace pb::cpu::avx2; the strategies use it where the CPU has AVX2 (checked at run
// time) and the scalar path step elsewhere.
#pragma GCC push_options
#pragma GCC target("avx2")
#define PB_SIMD_NS avx2
#include "shade_x8.h"
#undef PB_SIMD_NS
#pragma GCC pop_options
