#include "rank_tracer.h"

#include <algorithm>

#include <fmt/core.h>

#include "pathbench/common/errors.h"
#include "pathbench/cpu/render.h"
#include "pathbench/bvh/host_tracer.h"
#if PATHBENCH_HAVE_CUDA
#include "pathbench/gpu/render.h"
#endif

namespace pb::run {

struct RankTracer::Cpu {
  std::unique_ptr<cpu::EmbreeScene> scene;    // the CPU tracer's, or
  std::unique_ptr<gpu::HostGpuTracer> gpu_bvh;  // the GPU's samples on this CPU
};

struct RankTracer::Gpu {
#if PATHBENCH_HAVE_CUDA
  Gpu(const Scene& s, Instancing instancing) : scene(s, instancing) {}
  gpu::GpuScene scene;
  gpu::DeviceFilm film;  // every block's samples, downloaded once (finish)
#endif
};

RankTracer::RankTracer(const Scene& scene, const RenderSettings& settings, const RunOptions& options, bool gpu_samples)
    : scene_(scene), settings_(settings), options_(options) {
  settings_.validate();
  if (settings_.device == Device::Cpu) {
    // Built once for every chunk (a million-triangle scene takes Embree a second).
    cpu_ = std::make_unique<Cpu>();
    if (gpu_samples) cpu_->gpu_bvh = std::make_unique<gpu::HostGpuTracer>(scene, settings_.instancing);
    else cpu_->scene = cpu::make_embree_scene(scene, settings_.watertight, settings_.embree_layout,
                                                      settings_.instancing);
  } else {
    std::string why;
    if (!gpu_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
#if PATHBENCH_HAVE_CUDA
    gpu_ = std::make_unique<Gpu>(scene, settings_.instancing);  // BVH built and uploaded once for every chunk
#endif
  }
}

RankTracer::~RankTracer() = default;

const char* RankTracer::tracer() const {
  if (!cpu_) return "gpu";
  return cpu_->gpu_bvh ? "gpu-bvh-on-host" : "embree";
}

void RankTracer::trace(const FrameBlock& block, Film& film, RunReport& report) {
  RenderSettings s = settings_;
  s.first_row = block.first_row;
  s.row_count = block.rows;
  s.first_sample = block.first_sample;
  s.sample_count = block.samples;
  s.progress = false;  // ranks' bars would interleave on one terminal
  RunReport chunk;
  if (s.device == Device::Cpu && cpu_->gpu_bvh) {
    if (chunks_ == 0) {  // what cpu::render reports of itself
      chunk.settings = s;
      chunk.threads = s.threads > 0 ? s.threads : hardware_threads();
      chunk.extra["tracer"] = tracer();
      chunk.extra["bvh_layout"] = cpu_->gpu_bvh->layout();
    }
    cpu_->gpu_bvh->render(s, film, chunk);  // Film::add accumulates into the rank's film
    chunk.tracer_host_bytes = film.bytes() + cpu_->gpu_bvh->bvh_bytes();
  } else if (s.device == Device::Cpu) {
    cpu::render(scene_, *cpu_->scene, s, film, chunk);  // Film::add accumulates into the rank's film
  } else {
#if PATHBENCH_HAVE_CUDA
    // Every block adds into the device's film; it comes back once, in finish().
    gpu::render(scene_, gpu_->scene, s, film, chunk, options_.profile, &gpu_->film);
#endif
  }
  // The first chunk's description (device, memory, layout) stands for the rank's;
  // counts and times add up over chunks.
  if (chunks_++ == 0) {
    const RayCounts none;
    report = chunk;
    report.rays = none;
    report.paths = report.discarded_samples = 0;
    report.seconds = report.device_seconds = 0;
  }
  report.rays += chunk.rays;
  report.paths += chunk.paths;
  report.discarded_samples += chunk.discarded_samples;
  report.seconds += chunk.seconds;
  report.device_seconds += chunk.device_seconds;
  report.peak_device_bytes = std::max(report.peak_device_bytes, chunk.peak_device_bytes);
  report.tracer_host_bytes = std::max(report.tracer_host_bytes, chunk.tracer_host_bytes);
}

void RankTracer::warm_up(Film& film) {
#if PATHBENCH_HAVE_CUDA
  if (!gpu_) return;
  // One sample of the first row into the device film (kernels loaded, the film allocated
  // and touched), then cleared: `film` itself is not written.
  RenderSettings w = settings_;
  w.row_count = w.sample_count = 1;
  w.progress = false;
  RunReport ignored;
  gpu::render(scene_, gpu_->scene, w, film, ignored, false, &gpu_->film);
  gpu_->film.clear();
#else
  (void)film;
#endif
}

void RankTracer::finish(Film& film, RunReport& report) {
#if PATHBENCH_HAVE_CUDA
  if (gpu_ && gpu_->film.used()) report.extra["film_download_seconds"] = gpu_->film.download(film);
#else
  (void)film, (void)report;
#endif
}

double RankTracer::calibrate(const FrameBlock& block, Film& film, float max_emission) {
  RunReport probe;
  trace(block, film, probe);
  chunks_ = 0;  // the frame's first block describes the rank
#if PATHBENCH_HAVE_CUDA
  if (gpu_) gpu_->film.clear();
#endif
  if (!gpu_) film.begin(settings_.spp, max_emission);
  return probe.seconds;
}

gpu::DeviceFilm* RankTracer::device_film() {
#if PATHBENCH_HAVE_CUDA
  if (gpu_ && gpu_->film.used()) return &gpu_->film;
#endif
  return nullptr;
}

}  // namespace pb::run
