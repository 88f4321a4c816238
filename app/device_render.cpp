#include "device_render.h"

#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "pathbench/cpu/render.h"
#if PATHBENCH_HAVE_CUDA
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

void write_text_file(const std::string& path, const std::string& text) {
  std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error(fmt::format("{}: write failed", path));
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace pb::app
