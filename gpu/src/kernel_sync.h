#pragma once
// Programmatic dependent launch on the device side (sm_90+; a no-op on older targets,
// where the launch attribute has no effect either). Launcher::launch lets a kernel
// start before the previous kernel in its stream has finished, so every kernel it
// launches begins with:
//   pdl_trigger(): this grid's dependants may be scheduled now (they wait anyway);
//   pdl_wait():    block until the previous grid has completed and its memory is
//                  visible. Before it, a kernel must not read anything produced upstream.
#include <cstdint>

namespace pb::gpu {

constexpr unsigned kFullMask = 0xFFFFFFFFu;  // every lane of a warp (__shfl_sync, __reduce_add_sync)

__device__ __forceinline__ void pdl_trigger() {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
  asm volatile("griddepcontrol.launch_dependents;" ::: "memory");
#endif
}

__device__ __forceinline__ void pdl_wait() {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900
  asm volatile("griddepcontrol.wait;" ::: "memory");
#endif
}

// Both, at the top of every kernel launched through Launcher.
__device__ __forceinline__ void kernel_prologue() {
  pdl_trigger();
  pdl_wait();
}

// Grid-stride loops: this thread's index and the grid's thread count.
__device__ __forceinline__ uint32_t grid_thread() { return blockIdx.x * blockDim.x + threadIdx.x; }
__device__ __forceinline__ uint32_t grid_threads() { return gridDim.x * blockDim.x; }

}  // namespace pb::gpu
