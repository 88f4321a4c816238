// The CUDA tracer behind run/'s tracer interface (pathbench/run/tracer.h): the one place
// where the run layer's calls meet gpu/'s API. Plain C++ (host compiler).
#include <stdexcept>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/gpu/device_facts.h"
#include "pathbench/gpu/render.h"
#include "pathbench/run/tracer.h"
#include "bvh_names.h"

namespace pb::gpu {

namespace {

class GpuDeviceFilm final : public run::DeviceFilm {
 public:
  bool used() const override { return film.used(); }
  void clear() override { film.clear(); }
  double download(Film& f) const override { return film.download(f); }
  Arrays arrays() override {
    const gpu::DeviceFilm::Arrays a = film.arrays();
    return {a.sums, a.counts, a.sum_sq, a.pixels};
  }
  uint64_t max_abs_sum() const override { return film.max_abs_sum(); }
  gpu::DeviceFilm film;
};

class GpuPreparedScene final : public run::PreparedScene {
 public:
  GpuPreparedScene(const Scene& scene, Instancing instancing) : scene_(scene), gpu_(scene, instancing) {}
  GpuPreparedScene(const Scene& scene, const bvh::GpuBvhOptions& options) : scene_(scene), gpu_(scene, options) {}
  void render(const RenderSettings& s, Film& film, RunReport& report, bool profile,
              run::DeviceFilm* keep) const override {
    gpu::DeviceFilm* device = keep ? &dynamic_cast<GpuDeviceFilm&>(*keep).film : nullptr;
    gpu::render(scene_, gpu_, s, film, report, profile, device);
  }
  std::vector<double> time_rays(const std::vector<run::RayQuery>& rays, bool any_hit, int repeats) const override {
    std::vector<TraceQuery> q(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) q[i] = {rays[i].o, rays[i].d, rays[i].t_max};
    return time_trace_on_device(gpu_, q, any_hit, repeats);
  }

 private:
  const Scene& scene_;
  GpuScene gpu_;
};

class CudaTracer final : public run::Tracer {
 public:
  bool available(std::string* why_not) const override { return device_available(why_not); }
  void render(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report,
              bool profile) const override {
    gpu::render(scene, s, film, report, profile);
  }
  std::unique_ptr<run::PreparedScene> prepare(const Scene& scene, const RenderSettings& s) const override {
    return std::make_unique<GpuPreparedScene>(scene, s.instancing);
  }
  std::unique_ptr<run::PreparedScene> prepare_bvh(const Scene& scene,
                                                  const bvh::GpuBvhOptions& options) const override {
    return std::make_unique<GpuPreparedScene>(scene, options);
  }
  std::unique_ptr<run::DeviceFilm> make_device_film() const override { return std::make_unique<GpuDeviceFilm>(); }
  nlohmann::json fingerprint() const override { return device_fingerprint(); }
  std::string machine_slug() const override { return device_info().slug; }
  int device_count() const override { return gpu::device_count(); }
  int select_device(int local_rank) const override { return gpu::select_device(local_rank); }
};

}  // namespace

}  // namespace pb::gpu

namespace pb::run {

const Tracer& gpu_tracer() {
  static const gpu::CudaTracer t;
  return t;
}

}  // namespace pb::run
