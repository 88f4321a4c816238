// Traversal alone on the device: the BVH tests' closest/any-hit queries and the raw
// ray-cast benchmark's timed launches.
#include <cuda_runtime.h>

#include <stdexcept>
#include <vector>

#include "cuda_util.h"
#include "device_facts.h"
#include "gpu_scene_impl.cuh"
#include "kernel_sync.h"
#include "pathbench/common/errors.h"
#include "pathbench/bvh/traversal.h"
#include "pathbench/gpu/render.h"
#include "bvh_names.h"

namespace pb::gpu {

namespace {
// Traversal for tests and the ray-cast benchmarks, compiled for the BVH layout.
template <int kKind>
__global__ void k_trace(BvhView bvh, const TraceQuery* rays, TraceResult* out, uint32_t n, bool any_hit) {
  kernel_prologue();
  for (uint32_t i = grid_thread(); i < n; i += grid_threads()) {
    const TraceQuery r = rays[i];
    float t = r.t_max;
    uint32_t prim = any_hit ? traverse<true, true, kKind>(bvh, r.o, r.d, r.t_max, t)
                            : traverse<false, true, kKind>(bvh, r.o, r.d, r.t_max, t);
    out[i] = {prim, t};
  }
}

}  // namespace

std::vector<TraceResult> trace_on_device(const Scene& scene, const std::vector<TraceQuery>& rays, bool any_hit) {
  return trace_on_device(scene, rays, any_hit, GpuBvhOptions::from_env());
}

std::vector<TraceResult> trace_on_device(const Scene& scene, const std::vector<TraceQuery>& rays, bool any_hit,
                                         const GpuBvhOptions& options) {
  ensure_device();
  const GpuScene gs(scene, options);
  DeviceBuffer<TraceQuery> d_rays(rays.size(), "test rays", "the number of rays");
  DeviceBuffer<TraceResult> d_out(rays.size(), "test results", "the number of rays");
  d_rays.upload(rays.data(), rays.size());
  std::vector<TraceResult> out(rays.size());
  if (rays.empty()) return out;
  Launcher launch(nullptr, false);
  with_traversal_kind(gs.impl().bvh, [&](auto kind) {
    launch.launch("trace", k_trace<decltype(kind)::value>, rays.size(), gs.impl().bvh, d_rays.get(), d_out.get(),
                  uint32_t(rays.size()), any_hit);
  });
  PB_CUDA_CHECK(cudaDeviceSynchronize());
  d_out.download(out.data(), out.size());
  return out;
}

std::vector<double> time_trace_on_device(const GpuScene& gs, const std::vector<TraceQuery>& rays, bool any_hit,
                                         int repeats) {
  ensure_device();
  if (rays.empty() || repeats < 1) throw InputError("time_trace_on_device: needs rays and at least one repeat");
  const uint32_t n = uint32_t(rays.size());
  DeviceBuffer<TraceQuery> d_rays(n, "benchmark rays", "the number of rays");
  DeviceBuffer<TraceResult> d_out(n, "benchmark results", "the number of rays");
  d_rays.upload(rays.data(), n);
  Launcher launch(nullptr, false);
  const ScopedEvent start, stop;
  std::vector<double> seconds;
  for (int r = -1; r < repeats; ++r) {  // r = -1: warm-up, not timed
    PB_CUDA_CHECK(cudaMemset(d_out.get(), 0xAB, sizeof(TraceResult) * n));  // poison
    PB_CUDA_CHECK(cudaEventRecord(start.e, nullptr));
    with_traversal_kind(gs.impl().bvh, [&](auto kind) {
      launch.launch("trace", k_trace<decltype(kind)::value>, n, gs.impl().bvh, d_rays.get(), d_out.get(), n, any_hit);
    });
    PB_CUDA_CHECK(cudaEventRecord(stop.e, nullptr));
    PB_CUDA_CHECK(cudaEventSynchronize(stop.e));
    float ms = 0;
    PB_CUDA_CHECK(cudaEventElapsedTime(&ms, start.e, stop.e));
    if (r >= 0) seconds.push_back(double(ms) * 1e-3);
  }
  std::vector<TraceResult> out(n);
  d_out.download(out.data(), n);
  for (const TraceResult& t : out)
    if (t.prim == 0xABABABABu) throw std::runtime_error("time_trace_on_device: a result was not written");
  return seconds;
}

}  // namespace pb::gpu
