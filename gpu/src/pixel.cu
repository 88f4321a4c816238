// The pixel strategy: one megakernel, one thread per pixel sample (grid-stride over all
// samples of the frame, a warp taking 32 consecutive samples), the whole path in
// registers. Samples of one pixel are summed in the warp (exact integer sums) before one
// atomic per pixel.
#include <cuda_runtime.h>

#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "kernel_sync.h"
#include "path_step.cuh"
#include "pathbench/gpu/traversal.h"
#include "strategies.cuh"

namespace pb::gpu {

namespace {

// The block's ray and path counts, one atomic per counter per block. (Discarded samples
// are counted where they are rejected, in film_add_warp.)
__device__ void block_stats_add(Stats* stats, uint32_t bounce, uint32_t shadow, uint32_t paths) {
  __shared__ unsigned long long acc[3];
  if (threadIdx.x < 3) acc[threadIdx.x] = 0;
  __syncthreads();
  bounce = __reduce_add_sync(kFullMask, bounce);
  shadow = __reduce_add_sync(kFullMask, shadow);
  paths = __reduce_add_sync(kFullMask, paths);
  if ((threadIdx.x & 31) == 0) {
    atomicAdd(&acc[0], bounce);
    atomicAdd(&acc[1], shadow);
    atomicAdd(&acc[2], paths);
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    atomicAdd(&stats->bounce, acc[0]);
    atomicAdd(&stats->shadow, acc[1]);
    atomicAdd(&stats->paths, acc[2]);
    atomicAdd(&stats->camera, acc[2]);
  }
}

template <bool kVariance, uint32_t Kinds, class T, bool kWatertight, int kKind>
// Blocks an SM must fit (registers capped to match); 1 = the compiler's choice (80
// registers: 3 blocks of 256). PB_PIXEL_MIN_BLOCKS overrides it for experiments.
#ifndef PB_PIXEL_MIN_BLOCKS
#define PB_PIXEL_MIN_BLOCKS 1
#endif
__global__ void __launch_bounds__(256, PB_PIXEL_MIN_BLOCKS) k_pixel(SceneView s, BvhView bvh, PathConfig c, uint32_t spp, uint64_t total,
                                               FilmDev film, Stats* stats) {
  kernel_prologue();
  const uint32_t lane = threadIdx.x & 31;
  const uint64_t warp = (uint64_t(blockIdx.x) * blockDim.x + threadIdx.x) >> 5;
  const uint64_t warps = (uint64_t(gridDim.x) * blockDim.x) >> 5;
  uint32_t n_bounce = 0, n_shadow = 0, n_paths = 0;
  for (uint64_t base = warp * 32; base < total; base += warps * 32) {
    const uint64_t g = base + lane;
    const bool valid = g < total;
    const uint32_t pixel = valid ? c.first_pixel + uint32_t(g / spp) : 0xFFFFFFFFu;
    Vec3f L{0.0f, 0.0f, 0.0f};
    if (valid) {
      L = trace_path_bvh<Kinds, T, kWatertight, kKind>(s, bvh, c, pixel, c.first_sample + uint32_t(g % spp), n_bounce, n_shadow);
      ++n_paths;
    }
    film_add_warp<kVariance>(film, valid, pixel, L, &stats->discarded);
  }
  block_stats_add(stats, n_bounce, n_shadow, n_paths);
}

}  // namespace

FrameResult run_pixel(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c, uint32_t spp,
                      uint64_t total, FilmDev film, bool variance, Precision precision, bool watertight,
                      DeviceBuffer<Stats>& stats) {
  PB_CUDA_CHECK(cudaMemsetAsync(stats.get(), 0, sizeof(Stats), stream));
  // The megakernel compiled for the scene's material kinds (features.h).
  // In float with the watertight test, compiled for the scene's BVH layout; or (the
  // accuracy study's variants) in double or with Moeller-Trumbore, switching on it.
  with_features(g.view.material_kinds, [&](auto kinds) {
    constexpr uint32_t K = decltype(kinds)::value;
    auto go = [&](auto kernel) { launch.launch("pixel", kernel, 0, g.view, g.bvh, c, spp, total, film, stats.get()); };
    constexpr int kAny = kAnyKind;
    if (precision == Precision::Double) variance ? go(k_pixel<true, K, double, true, kAny>) : go(k_pixel<false, K, double, true, kAny>);
    else if (!watertight) variance ? go(k_pixel<true, K, float, false, kAny>) : go(k_pixel<false, K, float, false, kAny>);
    else
      with_traversal_kind(g.bvh.kind, [&](auto kind) {
        constexpr int B = decltype(kind)::value;
        variance ? go(k_pixel<true, K, float, true, B>) : go(k_pixel<false, K, float, true, B>);
      });
  });
  FrameResult r;
  PB_CUDA_CHECK(cudaMemcpyAsync(&r.stats, stats.get(), sizeof(Stats), cudaMemcpyDeviceToHost, stream));
  PB_CUDA_CHECK(cudaStreamSynchronize(stream));
  r.state_bytes_per_path = 0;  // in registers
  return r;
}

}  // namespace pb::gpu
