#pragma once
// The pool of paths in flight that the wavefront and paper-queue strategies share: two
// compacted state buffers, the hits, the shadow records and the counters in device
// memory (layouts in wavefront_state.cuh), and the frame loop launching the stages
// (wavefront_stages.cuh) in path_pool.cu.
#include <cuda_runtime.h>

#include <cstdint>

#include "cuda_util.h"
#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "strategies.cuh"
#include "wavefront_state.cuh"

namespace pb::gpu {

class PathPool {
 public:
  PathPool(uint64_t capacity, ShadowUse shadows, const char* what, const char* lower)
      : capacity_(capacity), shadows_(shadows) {
    for (auto& b : buf_) b.allocate(capacity, what, lower);
    prim_.allocate(capacity, what, lower);
    if (shadows.records) {
      sh_o_.allocate(capacity, what, lower);
      sh_d_.allocate(capacity, what, lower);
      sh_ct_.allocate(capacity, what, lower);
      sh_L_.allocate(capacity, what, lower);
    }
    if (shadows.pairs) {
      sh_d2_.allocate(capacity, what, lower);
      sh_c2_.allocate(capacity, what, lower);
    }
    ctr_.allocate(1, what, lower);
    PB_CUDA_CHECK(cudaMallocHost(&host_ctr_, sizeof(WaveCounters)));
    PB_CUDA_CHECK(cudaHostAlloc(&planned_, kPlanSlots * sizeof(uint32_t), cudaHostAllocMapped));
  }
  ~PathPool() {
    if (planned_) cudaFreeHost(planned_);
    if (host_ctr_) cudaFreeHost(host_ctr_);
  }
  PathPool(const PathPool&) = delete;
  PathPool& operator=(const PathPool&) = delete;

  // Per path: two state buffers (current and next), the hit, and where the settings
  // trace shadow rays one shadow record (a second ray's 24 bytes where pairs occur).
  static uint64_t state_bytes(ShadowUse shadows) {
    return 2 * Buffers::bytes_per_path() + sizeof(uint32_t) +
           (shadows.records ? 3 * sizeof(float4) + sizeof(float2) : 0) +
           (shadows.pairs ? sizeof(float4) + sizeof(float2) : 0);
  }

  // A frame in steps (run_pools drives them, for one pool or several that share a frame):
  // begin() readies the pool for the frame's samples [first, first + count) on `stream`;
  // step() launches one iteration (trace, shade) on the launcher's stream and returns false
  // once the host has seen an iteration with nothing to trace; finish() waits for the
  // stream and returns the result.
  void begin(cudaStream_t stream, uint64_t first, uint64_t count, const GpuScene::Impl& g);
  bool step(Launcher& launch, const GpuScene::Impl& g, const PathConfig& c, FilmDev film, bool variance);
  FrameResult finish(cudaStream_t stream);

 private:
  struct Buffers {
    DeviceBuffer<float4> o, d, beta, L;
    void allocate(uint64_t n, const char* what, const char* lower) {
      o.allocate(n, what, lower);
      d.allocate(n, what, lower);
      beta.allocate(n, what, lower);
      L.allocate(n, what, lower);
    }
    PathSoA view() const { return {o.get(), d.get(), beta.get(), L.get()}; }
    static uint64_t bytes_per_path() { return 4 * sizeof(float4); }
  };
  uint64_t capacity_;
  ShadowUse shadows_;
  Buffers buf_[2];
  DeviceBuffer<uint32_t> prim_;
  DeviceBuffer<float4> sh_o_, sh_d_, sh_L_, sh_d2_;
  DeviceBuffer<float2> sh_ct_, sh_c2_;
  DeviceBuffer<WaveCounters> ctr_;
  WaveCounters* host_ctr_ = nullptr;  // the counters at the end of a frame
  // Mapped host memory: iteration i's trace kernel writes into slot i % kPlanSlots whether it
  // has paths to trace (run reads them while the GPU works, resets them to kNotPlanned).
  static constexpr int kPlanSlots = 8;
  uint32_t* planned_ = nullptr;
  // The frame in progress (begin .. finish).
  uint64_t end_ = 0;         // one past its last sample
  uint64_t it_ = 0;          // iterations launched
  uint64_t iterations_ = 0;  // iterations the frame took, once step() has returned false
  uint32_t counter_rounds_ = 0;
  cudaStream_t stream_ = nullptr;
};

// kWavefrontPools: pools a wavefront frame's samples are split among, each on a stream of its own: while
// one pool's kernel drains (its last chunks on a few SMs), the other's fill the rest.
// H100, paper-cornell 256x256x800 nee, 5 waves of paths in all, interleaved
// (results/nvidia-h100-80gb-hbm3/archive/wavefront-pools-52d7eea): 1 pool 15.29 ms, 2 pools 14.74,
// 3 pools 16.30; uniform 9.32 -> 8.68; ico:8 61.9 -> 56.9. Films bit-identical (exact sums).
// A frame of `total` samples that the pool holds at once (total <= paths_in_flight) has no
// refills whose kernels could overlap: one pool, whose kernels PDL chains with no launch gap
// (two made 32x32x16 and 128x128x4 wavefront frames 0.07 -> 0.12 ms on an H100:
// results/nvidia-h100-80gb-hbm3/archive/record-cd791c9). PATHBENCH_GPU_WAVEFRONT_POOLS=1..4
// overrides it (a bad value: InputError).
int wavefront_pools(uint64_t total, uint64_t paths_in_flight);

// One frame of `total` samples, stages launched until every path has ended, over one pool
// or several, each on its own stream (streams[0] the frame's: the others start after what it
// holds and it ends after them), their iterations launched in turn; `total` split into
// contiguous ranges. Stats summed, iterations the most any pool took, paths in flight and
// pool bytes summed.
FrameResult run_pools(PathPool* const* pools, const cudaStream_t* streams, int n, Launcher& launch,
                      const GpuScene::Impl& g, const PathConfig& c, uint64_t total, FilmDev film,
                      bool variance);

}  // namespace pb::gpu
