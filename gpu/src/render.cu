// The CUDA tracer's orchestration: one render = film buffers on the device, the
// strategy's resources (pixel.cu's counters, or path_pool.cu's pool), a warm-up frame,
// the timed frame between CUDA events, the film back to the host, and the report.
// The rooms it calls: device_film.cuh (film + counters), pixel.cu (megakernel),
// wavefront_state.cuh / wavefront_stages.cuh / path_pool.cu (wavefront, paper-queue),
// scene_upload.cu, device_facts.cu, trace.cu (traversal alone), cuda_util (launches).
// What a render sets up the same way every time (stream, events, launcher, counters, the
// device's facts; a kept film's pools) is kept for the process's next render: RenderCache
// (render_cache.cuh).
#include "pathbench/gpu/render.h"

#include <cuda_runtime.h>
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cuda_util.h"
#include "device_facts.h"
#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "path_pool.cuh"
#include "render_cache.cuh"
#include "pathbench/common/errors.h"
#include "pathbench/common/path.h"
#include "strategies.cuh"
#include "bvh_names.h"

#ifndef PATHBENCH_CUDA_ARCHS
#define PATHBENCH_CUDA_ARCHS "?"
#endif

namespace pb::gpu {

struct DeviceFilm::Impl {
  FilmBuffers fb;
  bool used = false;
  uint32_t width = 0, height = 0;
  bool variance = false;
};

DeviceFilm::DeviceFilm() : impl_(std::make_unique<Impl>()) {}
DeviceFilm::~DeviceFilm() = default;
bool DeviceFilm::used() const { return impl_->used; }
void DeviceFilm::clear() {
  if (!impl_->used) return;
  impl_->fb.clear(nullptr);
  PB_CUDA_CHECK(cudaDeviceSynchronize());
}

namespace {
// Film back to the host: the device's unsigned sums are Film's int64 sums mod 2^64.
double download_film(const FilmBuffers& fb, Film& film) {
  static_assert(sizeof(unsigned long long) == sizeof(int64_t));
  const auto t0 = std::chrono::steady_clock::now();
  fb.sum.download(reinterpret_cast<unsigned long long*>(film.raw_sums().data()), fb.sum.size());
  fb.count.download(film.counts().data(), fb.count.size());
  if (film.has_variance()) fb.sum_sq.download(film.raw_sum_sq().data(), fb.sum_sq.size());
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void render_impl(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film,
                 RunReport& report, bool profile, DeviceFilm* keep);
}  // namespace

double DeviceFilm::download(Film& film) const {
  const Impl& d = *impl_;
  if (!d.used) throw std::logic_error("DeviceFilm::download: nothing was rendered into it");
  if (film.width() != d.width || film.height() != d.height || film.has_variance() != d.variance)
    throw std::logic_error("DeviceFilm::download: the film's size or variance differs from the device film's");
  return download_film(d.fb, film);
}

DeviceFilm::Arrays DeviceFilm::arrays() {
  Impl& d = *impl_;
  if (!d.used) throw std::logic_error("DeviceFilm::arrays: nothing was rendered into it");
  return {d.fb.sum.get(), d.fb.count.get(), d.fb.sum_sq.get(), d.fb.count.size()};
}

uint64_t max_abs_sum_on_device(const unsigned long long* sums, uint64_t n);  // film_ops.cu
uint64_t DeviceFilm::max_abs_sum() const {
  const Impl& d = *impl_;
  if (!d.used) throw std::logic_error("DeviceFilm::max_abs_sum: nothing was rendered into it");
  return max_abs_sum_on_device(d.fb.sum.get(), d.fb.sum.size());
}

void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report, bool profile) {
  // Start the context before measuring memory: its own use is not the tracer's.
  PB_CUDA_CHECK(cudaFree(nullptr));
  DeviceMemory::instance().begin_measurement();
  GpuScene gpu_scene(scene, settings.instancing);
  render_impl(scene, gpu_scene, settings, film, report, profile, nullptr);
}

void render(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film, RunReport& report,
            bool profile, DeviceFilm* keep) {
  // A kept film's later renders (an MPI rank's chunks) go on with its first render's
  // measurement: the same film, scene and kept resources (two cudaMemGetInfo calls less).
  if (!keep || !keep->used() || !render_cache_enabled()) DeviceMemory::instance().begin_measurement();
  render_impl(scene, gpu_scene, settings, film, report, profile, keep);
}

namespace {
// 1. Setup: the film on the device (this render's own, or a kept one that earlier renders,
// an MPI rank's chunks, added into, allocated and warmed up by the first of them), and the
// strategy's resources sized for the render's samples. The run layer has checked the
// settings for the GPU (validate_for_tracer) and the device (device_info is cached).
struct RenderSetup {
  RenderSetup(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& s, const Film& film, bool profile,
              DeviceFilm* keep, RenderCache* cache);
  // The kernels of the settings' strategy over `n` of the render's samples.
  FrameResult run_frame(uint64_t n, bool variance);

  const RenderSettings& settings;
  RenderCache* const cache;  // null: everything below is this render's own
  const DeviceInfo info;
  const std::string driver;
  const GpuScene::Impl& g;
  const PathConfig config;
  // Samples [first_sample, first_sample + traced_spp()) of each pixel (an MPI rank's share):
  // the kernels map g to (pixel g / config.spp, sample config.first_sample + g % config.spp).
  const uint64_t total;
  const ShadowUse shadows;

  std::unique_ptr<ScopedStream> own_stream;  // without a cache
  const cudaStream_t stream;
  std::unique_ptr<Launcher> own_launch;  // without a cache, or profiling
  Launcher& launch;
  FilmBuffers own;
  FilmBuffers& fb;
  const bool first_use;

  std::vector<std::unique_ptr<PathPool>> own_pools;  // wavefront: wavefront_pools(...) of them; paper-queue: one
  std::vector<std::unique_ptr<ScopedStream>> own_pool_streams;  // the wavefront's pools beyond the first
  DeviceBuffer<PixelCounters> own_pixel_counters;
  DeviceBuffer<PixelCounters>& pixel_counters;
  size_t pool_count = 0;
  uint64_t warmup_total;
  PixelOccupancy occupancy;
  std::vector<PathPool*> pool_ptrs;
  std::vector<cudaStream_t> pool_stream_ids;  // pool k's stream: the render's, then pool_streams
};

RenderSetup::RenderSetup(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& s, const Film& film,
                         bool profile, DeviceFilm* keep, RenderCache* c)
    : settings(s),
      cache(c),
      info(c ? c->info : device_info()),
      driver(c ? c->driver : kernel_driver_version()),
      g(gpu_scene.impl()),
      config(s.path_config()),
      total(s.traced_samples()),
      shadows(ShadowUse::of(scene, s)),
      own_stream(c ? nullptr : std::make_unique<ScopedStream>()),
      stream(c ? c->stream.s : own_stream->s),
      own_launch(c && !profile ? nullptr : std::make_unique<Launcher>(stream, profile)),
      launch(own_launch ? *own_launch : c->launch),
      fb(keep ? keep->impl().fb : own),
      first_use(!keep || !keep->impl().used),
      pixel_counters(c ? c->pixel_counters : own_pixel_counters) {
  if (!own_launch) {  // the kept launcher, as a new one starts
    launch.set_stream(stream);
    launch.clear();
  }
  const uint32_t pixels = s.width * s.height;
  if (keep && keep->impl().used) {
    const DeviceFilm::Impl& k = keep->impl();
    if (k.width != film.width() || k.height != film.height() || k.variance != film.has_variance())
      throw std::logic_error("gpu::render: the kept device film's size or variance differs from the film's");
  }
  if (first_use) fb.allocate(film, pixels);

  warmup_total = std::min<uint64_t>(total, pixels);
  std::vector<std::unique_ptr<PathPool>>* pools = &own_pools;
  std::vector<std::unique_ptr<ScopedStream>>* pool_streams = &own_pool_streams;
  if (s.strategy == Strategy::Pixel) {
    if (cache) cache->drop_pools();
    if (!pixel_counters.get()) pixel_counters.allocate(1, "counters", "nothing (a few bytes)");
  } else if (s.strategy == Strategy::Wavefront) {
    const uint64_t per_path = PathPool::state_bytes(shadows), in_use = fb.bytes() + g.bytes;
    uint64_t pif = s.paths_in_flight;
    if (!pif && cache && cache->pif && cache->pif_bytes_per_path == per_path && cache->pif_bytes_in_use == in_use)
      pif = cache->pif;
    if (!pif) {
      pif = default_paths_in_flight(per_path, in_use);
      if (cache) cache->pif_bytes_per_path = per_path, cache->pif_bytes_in_use = in_use, cache->pif = pif;
    }
    pif = std::min<uint64_t>(pif, total);
    pif = std::max<uint64_t>(pif, 1);
    if (pif > 0xFFFFFFFFull) throw InputError("--paths-in-flight: at most 4294967295 paths");
    // Under --profile one pool: each stage's events then bracket its own work alone.
    const uint64_t n = std::min<uint64_t>(profile ? 1 : uint64_t(wavefront_pools(total, pif)), pif);
    std::vector<uint64_t> caps;
    for (uint64_t k = 0; k < n; ++k) caps.push_back(pif * (k + 1) / n - pif * k / n);  // pif split as evenly as it goes
    if (cache && keep) {
      // A kept film's chunks: the cached pools where they are the same, else new ones in
      // their place (the old released first: no two sets at once).
      pools = &cache->pools;
      pool_streams = &cache->pool_streams;
      const bool same = cache->pool_caps == caps && cache->pool_shadows.records == shadows.records &&
                        cache->pool_shadows.pairs == shadows.pairs;
      if (!same) cache->drop_pools();
    } else if (cache) {  // a render of its own: no pools kept beside it
      cache->drop_pools();
    }
    if (pools->empty()) {
      for (uint64_t k = 0; k < n; ++k) {
        pools->push_back(std::make_unique<PathPool>(caps[k], shadows, "the wavefront path pool", "--paths-in-flight"));
        if (k > 0) pool_streams->push_back(std::make_unique<ScopedStream>());
      }
      if (cache && pools == &cache->pools) {
        cache->pool_caps = caps;
        cache->pool_shadows = shadows;
      }
    }
  } else {
    // The paper's global queue: a task for every path of the frame, all at once (never kept:
    // and no kept pools beside it).
    if (cache) cache->drop_pools();
    const uint64_t per_task = PathPool::state_bytes(shadows);
    const uint64_t need = total * per_task;
    const uint64_t free_b = DeviceMemory::free_bytes();
    if (total > 0xFFFFFFFFull || need + (64ull << 20) > free_b)
      throw InputError(fmt::format(
          "--strategy paper-queue: the paper's global queue holds every path of the frame up front: {}x{} pixels x {} "
          "spp = {} tasks x {} bytes = {:.2f} GB, but the GPU ({}) has {:.2f} GB free{}; lower --spp or "
          "--width/--height, or use --strategy wavefront (memory bounded by --paths-in-flight)",
          s.width, s.height, s.spp, total, per_task, need / 1e9, info.name, free_b / 1e9,
          total > 0xFFFFFFFFull ? " (and more than 2^32 - 1 tasks cannot be indexed)" : ""));
    own_pools.push_back(std::make_unique<PathPool>(total, shadows, "the paper-queue global task queue",
                                                   "--spp or --width/--height"));
    warmup_total = total;  // its warm-up is the frame itself: the queue is sized for it
  }

  occupancy = s.strategy == Strategy::Pixel ? pixel_occupancy(g, info.l2_bytes, s.spp, s.max_bounces) : PixelOccupancy{};
  pool_stream_ids.push_back(stream);
  for (const auto& pool : *pools) pool_ptrs.push_back(pool.get());
  for (const auto& ps : *pool_streams) pool_stream_ids.push_back(ps->s);
  pool_count = pools->size();
}

FrameResult RenderSetup::run_frame(uint64_t n, bool variance) {
  if (settings.strategy == Strategy::Pixel)
    return run_pixel(launch, stream, g, config, n, fb.view, variance, settings.precision, settings.watertight,
                     pixel_counters, occupancy.min_blocks, occupancy.parked);
  return run_pools(pool_ptrs.data(), pool_stream_ids.data(), int(pool_ptrs.size()), launch, g, config, n, fb.view,
                   variance);
}

// 2. The frame: a warm-up (module load, first-touch of every buffer) on the film's first
// use, then the timed frame between CUDA events, then the film back to the host (not a
// kept film: its owner downloads it once, after its last render).
struct TimedFrame {
  FrameResult result;
  double seconds = 0;     // host wall clock around the frame
  float device_ms = 0;    // CUDA events around the frame
  double download_seconds = 0;
};

TimedFrame run_timed_frame(RenderSetup& su, Film& film, DeviceFilm* keep) {
  DeviceMemory& mem = DeviceMemory::instance();
  // A kept film's later renders add to what is there: the first one warmed up.
  if (su.first_use) {
    su.fb.clear(su.stream);
    su.run_frame(su.warmup_total, film.has_variance());
    PB_CUDA_CHECK(cudaStreamSynchronize(su.stream));
    mem.sample();
    su.launch.clear();
    su.fb.clear(su.stream);
  }
  if (keep) {
    DeviceFilm::Impl& k = keep->impl();
    k.used = true;
    k.width = film.width();
    k.height = film.height();
    k.variance = film.has_variance();
  }

  TimedFrame t;
  std::unique_ptr<ScopedEvent> own0, own1;  // without a cache
  if (!su.cache) own0 = std::make_unique<ScopedEvent>(), own1 = std::make_unique<ScopedEvent>();
  const cudaEvent_t e0 = su.cache ? su.cache->ev0.e : own0->e, e1 = su.cache ? su.cache->ev1.e : own1->e;
  PB_CUDA_CHECK(cudaStreamSynchronize(su.stream));
  const auto t0 = std::chrono::steady_clock::now();
  PB_CUDA_CHECK(cudaEventRecord(e0, su.stream));
  t.result = su.run_frame(su.total, film.has_variance());
  PB_CUDA_CHECK(cudaEventRecord(e1, su.stream));
  PB_CUDA_CHECK(cudaEventSynchronize(e1));
  const auto t1 = std::chrono::steady_clock::now();
  // A kept film's later renders: its first render's measurement stands (render()).
  if (su.first_use || !su.cache) mem.sample();
  PB_CUDA_CHECK(cudaEventElapsedTime(&t.device_ms, e0, e1));
  t.seconds = std::chrono::duration<double>(t1 - t0).count();

  t.download_seconds = keep ? 0.0 : download_film(su.fb, film);
  return t;
}

// 3. The report: the frame's counts and times, the device's memory, and report.extra's
// GPU sections (the device, the BVH, the strategy's pools or occupancy, the profile).
void fill_report(RenderSetup& su, const TimedFrame& t, const Film& film, bool profile, bool kept, RunReport& report) {
  const RenderSettings& settings = su.settings;
  const GpuScene::Impl& g = su.g;
  const DeviceInfo& info = su.info;
  const FrameResult& r = t.result;
  const DeviceMemory& mem = DeviceMemory::instance();
  const float device_ms = t.device_ms;
  report.seconds = t.seconds;
  report.device_seconds = double(device_ms) / 1e3;
  report.rays.camera = r.stats.camera;
  report.rays.bounce = r.stats.bounce;
  report.rays.shadow = r.stats.shadow;
  report.paths = r.stats.paths;
  report.discarded_samples = r.stats.discarded;
  report.state_bytes_per_path = r.state_bytes_per_path;
  report.paths_in_flight = r.paths_in_flight;
  report.threads = 0;
  report.tracer_host_bytes = film.bytes();
  report.peak_device_bytes = std::max(mem.peak_allocated(), mem.peak_meminfo_delta());
  auto& x = report.extra;
  x["gpu"] = {{"name", info.name},
              {"slug", info.slug},
              {"compute_capability", fmt::format("{}.{}", info.compute_major, info.compute_minor)},
              {"multiprocessors", info.multiprocessors},
              {"memory_bytes", info.total_memory},
              {"l2_bytes", info.l2_bytes},
              {"driver_version", su.driver},
              {"driver_cuda_version", fmt::format("{}.{}", info.driver_version / 1000, (info.driver_version % 1000) / 10)},
              {"cuda_runtime_version", fmt::format("{}.{}", info.runtime_version / 1000, (info.runtime_version % 1000) / 10)},
              {"cuda_architectures_built", PATHBENCH_CUDA_ARCHS}};
  x["device_bytes_allocated_peak"] = mem.peak_allocated();
  x["device_bytes_meminfo_delta_peak"] = mem.peak_meminfo_delta();
  x["film_device_bytes"] = su.fb.bytes();
  x["scene_device_bytes"] = g.bytes;
  x["bvh"] = {{"layout", to_string(g.layout)}, {"nodes", g.bvh_nodes}, {"node_bytes", g.bvh_node_bytes},
              {"triangle_refs", g.bvh_tris}, {"leaves", g.bvh_leaves}, {"depth", g.bvh_depth}, {"device_bytes", g.bvh_bytes},
              {"sah_cost", g.bvh_sah}, {"build_seconds", g.bvh_build_seconds}, {"treelet_passes", g.bvh_treelet_passes},
              {"builder", g.layout == GpuBvhLayout::Brute ? "none: every triangle tested"
                          : g.layout == GpuBvhLayout::Binary ? "embree rtcBuildBVH, binned SAH, binary"
                          : g.layout == GpuBvhLayout::Leaves ? "embree rtcBuildBVH, binned SAH, binary: its leaves, no inner nodes"
                          : g.layout == GpuBvhLayout::Rects ? "none: the triangles paired into axis-aligned rectangles"
                          : g.layout == GpuBvhLayout::RectsBinary
                              ? "the largest axis-aligned rectangles first, then embree rtcBuildBVH, binned SAH, binary over the rest"
                          : g.layout == GpuBvhLayout::TwoLevel
                              ? "embree rtcBuildBVH, binned SAH, binary: over the instances, and one per prototype"
                              : "embree rtcBuildBVH, binned SAH, binary (leaves <= 3), collapsed greedily"}};
  x["instancing"] = g.instancing;
  x["device_samples_per_second"] = device_ms > 0 ? double(r.stats.paths) / (device_ms / 1e3) : 0.0;
  x["device_rays_per_second"] = device_ms > 0 ? double(report.rays.total()) / (device_ms / 1e3) : 0.0;
  if (const char* commit = std::getenv("PATHBENCH_SOURCE_COMMIT")) x["source_commit"] = commit;
  x["timing"] = "device_seconds: CUDA events around the frame, after a warm-up frame";
  if (!kept) x["film_download_seconds"] = t.download_seconds;  // after the timed frame, not in it
  if (settings.strategy != Strategy::Pixel) {
    x["state_layout"] = std::string("2 x (o+pdf, d+pixel, beta+depth, L+sample: float4) + hit u32") +
                        (su.shadows.records ? " + shadow record (o, d: float4; c.z+target: float2; L of a finished path: float4)" : "") +
                        (su.shadows.pairs ? " + a pair's second ray (d: float4; c.yz: float2)" : "");
    x["pool_device_bytes"] = r.pool_bytes;
    x["iterations"] = r.iterations;
    x["counter_rounds"] = r.counter_rounds;  // work_chunks.cuh: the stages' last rounds from a counter
    x["pools"] = su.pool_count;  // path_pool.cuh: run_pools, each on a stream of its own
  }
  if (settings.strategy == Strategy::PaperQueue) {
    x["bytes_per_task"] = r.state_bytes_per_path;  // the queues are the compacted state buffers themselves
    x["tasks"] = su.total;
  }
  if (settings.strategy == Strategy::Pixel) {
    x["pixel_block"] = su.launch.block_size("pixel");
    if (settings.precision == Precision::Float && settings.watertight)
      x["pixel_occupancy"] = {{"min_blocks_per_sm", su.occupancy.min_blocks}, {"why", su.occupancy.why},
                              {"parked_path_state", su.occupancy.parked}, {"lanes_ordered_by_first_bounce", su.occupancy.lanes_ordered}};
  }
  if (profile) {
    const nlohmann::json prof = su.launch.collect();
    x["profile"] = prof;
    std::fputs(Launcher::format_table(prof).c_str(), stdout);
  }
  if (settings.strategy == Strategy::Pixel)
    x["paths_in_flight_note"] = su.occupancy.parked
                                    ? "pixel: one thread per sample, path state in the block's shared memory"
                                    : "pixel: one thread per sample, path state in registers";
}

void render_impl(const Scene& scene, const GpuScene& gpu_scene, const RenderSettings& settings, Film& film,
                 RunReport& report, bool profile, DeviceFilm* keep) {
  if (film.width() != settings.width || film.height() != settings.height)
    throw std::logic_error("film size does not match the settings");
  CacheLease lease;  // held until the report is filled
  RenderSetup setup(scene, gpu_scene, settings, film, profile, keep, lease.cache);
  const TimedFrame frame = run_timed_frame(setup, film, keep);
  fill_report(setup, frame, film, profile, keep != nullptr, report);
}
}  // namespace

}  // namespace pb::gpu
