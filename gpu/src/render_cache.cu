// The process's RenderCache (render_cache.cuh) and the lease a render takes on it.
#include "render_cache.cuh"

#include <cuda_runtime.h>
#include <fmt/core.h>

#include <cstdlib>

#include "device_facts.h"
#include "pathbench/common/errors.h"

namespace pb::gpu {

RenderCache::RenderCache(int d)
    : device(d), info(device_info()), driver(kernel_driver_version()), launch(stream.s, false) {}

bool render_cache_enabled() {
  static const bool on = [] {
    const char* v = std::getenv("PATHBENCH_GPU_RENDER_CACHE");
    const std::string s = v ? v : "";
    if (s.empty() || s == "1" || s == "on") return true;
    if (s == "0" || s == "off") return false;
    throw InputError(fmt::format("PATHBENCH_GPU_RENDER_CACHE='{}': expected 1, on, 0 or off", s));
  }();
  return on;
}

namespace {
std::mutex render_cache_mutex;
RenderCache* render_cache = nullptr;  // guarded by render_cache_mutex
}  // namespace

CacheLease::CacheLease() : lock(render_cache_mutex, std::defer_lock) {
  if (!render_cache_enabled() || !lock.try_lock()) return;
  ensure_device();  // no device: its InputError, as without the cache
  int device = 0;
  PB_CUDA_CHECK(cudaGetDevice(&device));
  if (!render_cache) render_cache = new RenderCache(device);
  if (render_cache->device == device) cache = render_cache;
  else lock.unlock();
}

}  // namespace pb::gpu
