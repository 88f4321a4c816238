#include "rank_tracer.h"

#include <algorithm>

#include <fmt/core.h>

#include "pathbench/bvh/host_tracer.h"
#include "pathbench/common/errors.h"

namespace pb::run {

RankTracer::RankTracer(const Scene& scene, const RenderSettings& settings, const RunOptions& options, bool gpu_samples)
    : settings_(settings), options_(options) {
  settings_.validate();
  if (settings_.device == Device::Cpu && gpu_samples) {
    host_bvh_ = std::make_unique<bvh::HostGpuTracer>(scene, settings_.instancing);
    return;
  }
  const Tracer& t = run::tracer(settings_.device);
  std::string why;
  if (!t.available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
  // Built once for every chunk (a million-triangle scene takes Embree a second; the GPU's
  // BVH is built and uploaded once).
  scene_ = t.prepare(scene, settings_);
  device_film_ = t.make_device_film();
}

RankTracer::~RankTracer() = default;

const char* RankTracer::tracer() const {
  if (host_bvh_) return "gpu-bvh-on-host";
  return settings_.device == Device::Gpu ? "gpu" : "embree";
}

void RankTracer::trace(const FrameBlock& block, Film& film, RunReport& report) {
  RenderSettings s = settings_;
  s.first_row = block.first_row;
  s.row_count = block.rows;
  s.first_sample = block.first_sample;
  s.sample_count = block.samples;
  s.progress = false;  // ranks' bars would interleave on one terminal
  RunReport chunk;
  if (host_bvh_) {
    if (chunks_ == 0) {  // what cpu::render reports of itself
      chunk.settings = s;
      chunk.threads = s.threads > 0 ? s.threads : hardware_threads();
      chunk.extra["tracer"] = tracer();
      chunk.extra["bvh_layout"] = host_bvh_->layout();
    }
    host_bvh_->render(s, film, chunk);  // Film::add accumulates into the rank's film
    chunk.tracer_host_bytes = film.bytes() + host_bvh_->bvh_bytes();
  } else {
    // The CPU adds into the rank's film; a GPU adds every block into its device film,
    // which comes back once, in finish().
    scene_->render(s, film, chunk, options_.profile, device_film_.get());
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
  if (!device_film_) return;
  // One sample of the first row into the device film (kernels loaded, the film allocated
  // and touched), then cleared: `film` itself is not written.
  RenderSettings w = settings_;
  w.row_count = w.sample_count = 1;
  w.progress = false;
  RunReport ignored;
  scene_->render(w, film, ignored, false, device_film_.get());
  device_film_->clear();
}

void RankTracer::finish(Film& film, RunReport& report) {
  if (device_film_ && device_film_->used()) report.extra["film_download_seconds"] = device_film_->download(film);
}

double RankTracer::calibrate(const FrameBlock& block, Film& film, float max_emission) {
  RunReport probe;
  trace(block, film, probe);
  chunks_ = 0;  // the frame's first block describes the rank
  if (device_film_) device_film_->clear();
  else film.begin(settings_.spp, max_emission);
  return probe.seconds;
}

DeviceFilm* RankTracer::device_film() {
  if (device_film_ && device_film_->used()) return device_film_.get();
  return nullptr;
}

}  // namespace pb::run
