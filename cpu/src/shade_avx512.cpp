// The batched path step for AVX-512: 16 lanes (shade_kernels.inc). The target implies
// FMA; -ffp-contract=off (top-level CMakeLists.txt) keeps a * b + c two roundings, as in
// the scalar path step.
#define PB_SIMD_NS avx512
#define PB_SIMD_LANES 16
#define PB_SIMD_TARGET "avx512f,avx512bw,avx512dq,avx512vl"
#include "shade_kernels.inc"

namespace pb::cpu {
const BatchKernels& avx512_kernels() {
  static const BatchKernels k{Isa::Avx512,
                              avx512::kLanes,
                              avx512::begin_paths_k,
                              avx512::final_vertex_candidates_k,
                              avx512::shade_diffuse_k,
                              avx512::rays_to_packet_k,
                              avx512::sincos_turns_k};
  return k;
}
}  // namespace pb::cpu
