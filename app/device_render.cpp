#include "device_render.h"

#include <fmt/core.h>

#include <stdexcept>

#include "pathbench/common/errors.h"
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

void render_on_device(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, bool profile) {
  if (s.device == Device::Cpu) {
    cpu::render(scene, s, film, report);
    return;
  }
  std::string why;
  if (!gpu_available(&why)) throw InputError(fmt::format("--device gpu: {}", why));
#if PATHBENCH_HAVE_CUDA
  gpu::render(scene, s, film, report, profile);
#else
  (void)profile;
#endif
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
