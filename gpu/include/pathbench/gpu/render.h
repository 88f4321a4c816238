#pragma once
// The CUDA tracer. Three strategies, all driven by the shared path step of common/:
//   pixel       megakernel, one thread per pixel sample, bounces looped in registers;
//   wavefront   a bounded pool of paths in flight (structure of arrays in device
//               memory), one kernel per stage linked by queues, refilled until done;
//   paper-queue the 2015 paper's design done correctly: every path of the frame
//               queued up front, then resolved stage by stage; refuses (InputError)
//               when that queue does not fit in device memory.
// Plain C++ header: the app includes it without nvcc.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::bvh {
struct GpuBvhOptions;
}  // namespace pb::bvh

namespace pb::gpu {

// True when a CUDA device can be used; otherwise false and *why_not says why.
bool device_available(std::string* why_not = nullptr);

struct DeviceInfo {
  std::string name;
  int device = 0;
  int compute_major = 0, compute_minor = 0;
  int multiprocessors = 0;
  uint64_t total_memory = 0;
  uint64_t l2_bytes = 0;     // the L2 cache (the pixel megakernel's occupancy rule reads it)
  int driver_version = 0;   // e.g. 13000
  int runtime_version = 0;
  std::string slug;         // results/<slug>/: "nvidia-h100-80gb-hbm3"
};
// Throws InputError when there is no device.
DeviceInfo device_info();
// For an MPI rank (run/): use device `local_rank % visible devices` from now on (call it
// before any other CUDA work of the process). Returns the device index chosen, or -1
// where there is none (device_available says why).
int select_device(int local_rank);
// Visible CUDA devices (0 where none).
int device_count();

using bvh::GpuBvhOptions;  // pathbench/bvh/bvh_layout.h

// The scene on the device: arrays and BVH, uploaded once, reusable for many renders.
// The BVH's layout comes from `options` (binary, wide4, wide8, brute force; bvh_layout.h),
// or from the environment (GpuBvhOptions::from_env: PATHBENCH_GPU_BVH, ...).
class GpuScene {
 public:
  explicit GpuScene(const Scene& scene);
  GpuScene(const Scene& scene, const GpuBvhOptions& options);
  // From the environment, with the render's --instancing (a two-level BVH where it applies).
  GpuScene(const Scene& scene, Instancing instancing);
  ~GpuScene();
  GpuScene(const GpuScene&) = delete;
  GpuScene& operator=(const GpuScene&) = delete;
  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// A film kept on the device across renders: an MPI rank's chunks (run/rank_tracer.cpp)
// add into it, and it comes back to the host once, instead of a film copy and a host-side
// addition per chunk. Its first render warms up (as every render does); later ones add.
class DeviceFilm {
 public:
  DeviceFilm();
  ~DeviceFilm();
  DeviceFilm(const DeviceFilm&) = delete;
  DeviceFilm& operator=(const DeviceFilm&) = delete;
  // Whether a render has added into it yet.
  bool used() const;
  // Zeroes its sums and counts, keeping the buffers (and the warm-up done): a rank warms
  // its GPU up with a render into it before the frame's clock starts, then clears it.
  void clear();
  // Replaces `film`'s sums and counts (and variance sums) with the device's: the sums of
  // every render into it. Returns the seconds the copy took.
  double download(Film& film) const;
  // Its arrays on the device, for a collective that reads and adds them in place (run/'s
  // NCCL reduction of MPI ranks' films): device pointers on this process's current
  // device, valid while the film lives. `sums` holds Film's int64 sums (two's complement),
  // 3 per pixel; `counts` uint32, one per pixel; `sum_sq` doubles, 3 per pixel, or null.
  // Throws std::logic_error before the first render into it.
  struct Arrays {
    void* sums = nullptr;
    void* counts = nullptr;
    void* sum_sq = nullptr;
    uint64_t pixels = 0;
  };
  Arrays arrays();
  // The largest |sum| of any pixel's channel, read on the device: the bound a reduction
  // of several films checks before it adds them without overflow checks.
  uint64_t max_abs_sum() const;
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Traces into `film` and fills the GPU's fields of `report`. Called by the run layer
// (pathbench/run/run.h), which has validated the settings, checked the device, sized
// and begun the film, and fills the common report fields. `profile`
// prints a per-stage table (name, launches, total ms, share) to stdout and adds it to
// report.extra["profile"]. Throws InputError for no device or device memory too small
// for the request (naming the setting to lower); settings the GPU cannot run are refused
// before, by validate_for_tracer (settings.h).
void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report, bool profile = false);
void render(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film,
            RunReport& report, bool profile = false, DeviceFilm* keep = nullptr);
// With `keep`, the samples are added into that device film (sized for `film` on its first
// use) and `film` is left untouched: DeviceFilm::download brings the sums back.

// Default pool size of the wavefront strategy on this device, for paths of
// `bytes_per_path` beside `bytes_in_use` (the film, the scene) already on the device.
// 7.5 waves of the device's threads: with two pools (path_pool.cuh) interleaved on an H100,
// paper-cornell 256x256x800 nee wavefront 14.74 ms at 5 waves, 13.70 at 7.5, 13.42 at 10
// (results/nvidia-h100-80gb-hbm3/archive/wavefront-pools-52d7eea). Capped so that pool, film and
// scene stay within kWavefrontBudgetBytes: issue 15 asks for at most 512 MB at any frame
// size, and beside the allocations the driver's meminfo grew by 53 MB (2048x2048
// paper-cornell) to 58 MB (ico:8) with two pools running (24-29 MB with one: local memory
// for concurrent kernels, it seems), so ~80 MB are left for that.
constexpr uint64_t kWavefrontPoolWaveHalves = 15;
constexpr uint64_t kWavefrontBudgetBytes = uint64_t(412) << 20;  // 432.0 MB
// Pools the wavefront splits a frame's samples among (gpu/src/path_pool.cuh says why).
constexpr int kWavefrontPools = 2;
uint64_t default_paths_in_flight(uint64_t bytes_per_path, uint64_t bytes_in_use);

// Traversal on the device, for tests: closest hit (or any hit when `any_hit`) for each
// ray with ray_t_min < t < t_max (watertight.h).
struct TraceQuery {
  Vec3f o, d;
  float t_max;
};
struct TraceResult {
  uint32_t prim;  // scene triangle id or 0xFFFFFFFF
  float t;
};
std::vector<TraceResult> trace_on_device(const Scene& scene, const std::vector<TraceQuery>& rays, bool any_hit);
std::vector<TraceResult> trace_on_device(const Scene& scene, const std::vector<TraceQuery>& rays, bool any_hit,
                                         const GpuBvhOptions& options);

// Ray casting alone, for the raw ray-cast benchmarks: the rays are uploaded once, the
// traversal kernel runs once to warm up, then `repeats` launches are each timed with
// CUDA events. Returns the device seconds of each timed launch. Throws if any result
// was left unwritten (the output is poisoned before every launch).
std::vector<double> time_trace_on_device(const GpuScene& scene, const std::vector<TraceQuery>& rays, bool any_hit,
                                         int repeats);

}  // namespace pb::gpu
