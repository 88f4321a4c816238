#pragma once
// What gpu::render keeps across the calls of a process (issue 30: the hybrid's GPU rank paid
// ~0.37 ms a call for it, outside the timed frame, and a one-GPU process none): the
// device's facts (cudaGetDeviceProperties, the driver's version file), the render's stream
// and timing events, the launcher (its stages' occupancy queries), the pixel strategy's
// counter block, and, for a kept film (an MPI rank's chunks), the wavefront's pools while
// the next chunk asks for pools of the same sizes. One device a cache (an MPI rank's): a
// render on another device, one while another thread renders, or any render with
// PATHBENCH_GPU_RENDER_CACHE=0 makes its own, as before. Never destroyed (CUDA may be torn
// down first at exit, as DeviceMemory's ledger says). render.cu uses it; render_cache.cu
// holds the process's one.
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cuda_util.h"
#include "path_pool.cuh"
#include "pathbench/gpu/render.h"
#include "strategies.cuh"

namespace pb::gpu {

struct RenderCache {
  explicit RenderCache(int d);
  const int device;
  const DeviceInfo info;
  const std::string driver;
  ScopedStream stream;
  ScopedEvent ev0, ev1;
  Launcher launch;  // not profiling: a profiled render's launcher records events of its own
  DeviceBuffer<PixelCounters> pixel_counters;
  // A kept film's wavefront pools, their sizes and shadow records.
  std::vector<std::unique_ptr<PathPool>> pools;
  std::vector<std::unique_ptr<ScopedStream>> pool_streams;
  std::vector<uint64_t> pool_caps;
  ShadowUse pool_shadows;
  // default_paths_in_flight's last answer (it reads the device's properties) and its question.
  uint64_t pif_bytes_per_path = 0, pif_bytes_in_use = 0, pif = 0;
  // Any render that does not use the kept pools releases them: no device memory is held
  // beside a render (or in its measurement) for pools it does not run.
  void drop_pools() {
    pools.clear();
    pool_streams.clear();
    pool_caps.clear();
  }
};

// PATHBENCH_GPU_RENDER_CACHE: unset, 1 or on (the default), 0 or off; else InputError.
bool render_cache_enabled();

// The cache for one render, held (locked) while the render lives; null where it cannot serve.
struct CacheLease {
  std::unique_lock<std::mutex> lock;
  RenderCache* cache = nullptr;
  CacheLease();
};

}  // namespace pb::gpu
