#pragma once
// The tracers as the run layer drives them: one interface per device, so that run/ (and
// bench/ and python/ through run/) never include a tracer's own headers. Each tracer's
// target implements it where that tracer is built:
//   cpu_tracer()  run/src/cpu_tracer.cpp   (the Embree + TBB tracer of cpu/)
//   gpu_tracer()  gpu/src/run_tracer.cpp   (the CUDA tracer), or run/src/no_gpu_tracer.cpp
//                                          in a build without CUDA (every call refuses)
// gpu/ includes this header; run/ never includes gpu/'s. Every member is defined in this
// header or by the implementations, so gpu/ needs nothing of run/'s library.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pathbench/common/film.h"
#include "pathbench/common/math.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::bvh {
struct GpuBvhOptions;
}  // namespace pb::bvh

namespace pb::run {

// A film kept on the device across renders: an MPI rank's chunks add into it, and it
// comes back to the host once. Its first render warms up; later ones add.
class DeviceFilm {
 public:
  virtual ~DeviceFilm() = default;
  // Whether a render has added into it yet.
  virtual bool used() const = 0;
  // Zeroes its sums and counts, keeping the buffers (and the warm-up done).
  virtual void clear() = 0;
  // Replaces `film`'s sums and counts (and variance sums) with the device's. Returns the
  // seconds the copy took.
  virtual double download(Film& film) const = 0;
  // Its arrays on the device, for a collective that adds them in place (the NCCL
  // reduction of MPI ranks' films): `sums` int64, 3 per pixel; `counts` uint32, one per
  // pixel; `sum_sq` doubles, 3 per pixel, or null. Throws before the first render into it.
  struct Arrays {
    void* sums = nullptr;
    void* counts = nullptr;
    void* sum_sq = nullptr;
    uint64_t pixels = 0;
  };
  virtual Arrays arrays() = 0;
  // The largest |sum| of any pixel's channel, read on the device.
  virtual uint64_t max_abs_sum() const = 0;
};

// A ray for the raw ray-cast benchmarks: closest (or any) hit with t < t_max.
struct RayQuery {
  Vec3f o, d;
  float t_max;
};

// A scene prepared once on a device (Embree's scene, or the GPU's uploaded BVH), then
// traced any number of times.
class PreparedScene {
 public:
  virtual ~PreparedScene() = default;
  // Traces into `film` (run/ has validated the settings and begun the film) and fills the
  // tracer's fields of `report`. With `keep` (a GPU's device film, from
  // Tracer::make_device_film), the samples add into that film and `film` is untouched.
  virtual void render(const RenderSettings& settings, Film& film, RunReport& report, bool profile = false,
                      DeviceFilm* keep = nullptr) const = 0;
  // Ray casting alone (GPU): one warm-up launch, then `repeats` timed launches over `rays`;
  // the device seconds of each. The CPU's prepared scene refuses (std::logic_error).
  virtual std::vector<double> time_rays(const std::vector<RayQuery>&, bool, int) const {
    throw std::logic_error("time_rays: ray casting alone is the GPU tracer's");
  }
};

class Tracer {
 public:
  virtual ~Tracer() = default;
  // True when this tracer can run here; otherwise false and *why_not says why.
  virtual bool available(std::string* why_not = nullptr) const = 0;
  // One render of `scene` (the scene prepared, traced, released).
  virtual void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report,
                      bool profile = false) const = 0;
  // The scene prepared for many renders with the render's settings (layout, instancing).
  virtual std::unique_ptr<PreparedScene> prepare(const Scene& scene, const RenderSettings& settings) const = 0;
  // The GPU's scene with an explicit BVH layout (bvh_layout.h), for the ray-cast
  // benchmarks; the CPU refuses (std::logic_error).
  virtual std::unique_ptr<PreparedScene> prepare_bvh(const Scene&, const bvh::GpuBvhOptions&) const {
    throw std::logic_error("prepare_bvh: only the GPU tracer takes a BVH layout");
  }
  // What this process measured to prepare `scene` with `settings` (the CPU's Embree layout
  // under --embree-layout auto: a timed probe), as one line of text; empty where nothing is
  // measured. MPI ranks all adopt rank 0's (adopt_measured), so every rank traces the layout
  // one process would and no rank's probe, timed beside the other ranks' start, picks
  // another (its samples would differ in low bits: issue 30). adopt_measured returns false
  // for a line it cannot read.
  virtual std::string measured(const Scene&, const RenderSettings&) const { return {}; }
  virtual bool adopt_measured(const Scene&, const RenderSettings&, const std::string&) const { return true; }
  // A film on the device for PreparedScene::render's `keep`; null where the tracer keeps none (CPU).
  virtual std::unique_ptr<DeviceFilm> make_device_film() const { return nullptr; }
  // The device's part of the machine fingerprint; null for the CPU (run_context.cpp adds Embree's and TBB's).
  virtual nlohmann::json fingerprint() const { return nullptr; }
  // The results/<machine>/ folder name of the device ("nvidia-h100-80gb-hbm3"); empty for the CPU.
  virtual std::string machine_slug() const { return {}; }
  // Devices visible to this process (0 for none; 1 for the CPU).
  virtual int device_count() const = 0;
  // For an MPI rank: use device `local_rank % device_count()` from now on, before any
  // other work of the process on it. Returns the device chosen, or -1.
  virtual int select_device(int local_rank) const = 0;
};

const Tracer& cpu_tracer();
const Tracer& gpu_tracer();
inline const Tracer& tracer(Device device) { return device == Device::Gpu ? gpu_tracer() : cpu_tracer(); }

}  // namespace pb::run
