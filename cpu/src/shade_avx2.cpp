// The batched path step for AVX2: 8 lanes (shade_kernels.inc).
#define PB_SIMD_NS avx2
#define PB_SIMD_LANES 8
#define PB_SIMD_TARGET "avx2"
#include "shade_kernels.inc"

namespace pb::cpu {
const BatchKernels& avx2_kernels() {
  static const BatchKernels k{Isa::Avx2,
                              avx2::kLanes,
                              avx2::begin_paths_k,
                              avx2::final_vertex_candidates_k,
                              avx2::shade_diffuse_k,
                              avx2::rays_to_packet_k,
                              avx2::sincos_turns_k};
  return k;
}
}  // namespace pb::cpu
