#include "device_render.h"

#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/cpu/embree_facts.h"
#include "pathbench/common/limits.h"
#include "pathbench/cpu/render.h"
#if PATHBENCH_HAVE_CUDA
#include "pathbench/gpu/device_facts.h"
#include "pathbench/gpu/render.h"
#endif

namespace pb::app {

bool gpu_available(std::string* why_not) {
#if PATHBENCH_HAVE_CUDA
  return pb::gpu::device_available(why_not);
#else
  if (why_not) *why_not = "this build has no CUDA tracer (configure with -DPATHBENCH_CUDA=ON and nvcc on PATH)";
  return false;
#endif
}

nlohmann::json run_fingerprint(bool with_gpu) {
  nlohmann::json fp = machine_fingerprint();
  const nlohmann::json& et = cpu::embree_tbb_facts();
  fp["embree"] = et["embree"];
  fp["libraries"]["embree"] = et["embree"].value("version", et["embree"]["version_compiled"].get<std::string>());
  fp["libraries"]["tbb"] = et["tbb"]["version"];
  fp["tbb"] = et["tbb"];
  if (!with_gpu) return fp;
  std::string why;
#if PATHBENCH_HAVE_CUDA
  if (gpu_available(&why)) {
    static const nlohmann::json gpu_facts = gpu::device_fingerprint();  // NVML is opened once per process
    fp["gpu"] = gpu_facts;
    return fp;
  }
#else
  gpu_available(&why);
#endif
  fp["gpu"] = {{"none", why}};
  return fp;
}

nlohmann::json load_sample() {
  return {{"load_average", load_average()},
          {"process_cpu_seconds", process_cpu_seconds()},
          {"wall_seconds", std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count()}};
}

nlohmann::json load_between(const nlohmann::json& start, const nlohmann::json& end) {
  const double cpu = end["process_cpu_seconds"].get<double>() - start["process_cpu_seconds"].get<double>();
  const double wall = end["wall_seconds"].get<double>() - start["wall_seconds"].get<double>();
  return {{"load_average_at_start", start["load_average"]},
          {"load_average_at_end", end["load_average"]},
          {"process_cpu_seconds", cpu},
          {"wall_seconds", wall},
          // About the thread count when the process had the cores to itself; well below it
          // when another process took them (wall time grows, CPU time does not).
          {"cpu_per_wall", wall > 0 ? nlohmann::json(cpu / wall) : nlohmann::json(nullptr)}};
}

// A film where most samples were discarded (NaN, infinite, or beyond its fixed-point
// range) is wrong, not noisy: fail rather than write it. Within the supported emission
// range this takes extreme geometry (a light 1e-10 from a wall, say).
void check_discarded(const Scene& scene, const RenderSettings& s, const RunReport& report) {
  const double samples = double(s.width) * double(s.height) * double(s.spp);
  const double discarded = double(report.discarded_samples);
  if (samples > 0 && discarded > limits::kMaxDiscardedFraction * samples)
    throw InputError(fmt::format("{}: {} of {} samples ({:.1f}%) were discarded as NaN, infinite or beyond the "
                                 "film's range; the image would be wrong, so none is written (emission is "
                                 "limited to {:g}; very bright lights very close to surfaces also overflow)",
                                 scene.name, report.discarded_samples, uint64_t(samples), 100 * discarded / samples,
                                 limits::kMaxEmission));
}

void render_on_device(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, bool profile) {
  const nlohmann::json start = load_sample();
  if (s.device == Device::Cpu) {
    cpu::render(scene, s, film, report);
  } else {
    std::string why;
    if (!gpu_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
#if PATHBENCH_HAVE_CUDA
    gpu::render(scene, s, film, report, profile);
#else
    (void)profile;
#endif
  }
  report.load = load_between(start, load_sample());
  report.fingerprint = run_fingerprint(s.device == Device::Gpu);
  check_discarded(scene, s, report);
}

double render_seconds(const RunReport& r) { return r.settings.device == Device::Gpu ? r.device_seconds : r.seconds; }

std::string machine_folder(Device device) {
#if PATHBENCH_HAVE_CUDA
  if (device == Device::Gpu) return gpu::device_info().slug;
#endif
  (void)device;
  return machine_slug();
}

}  // namespace pb::app
