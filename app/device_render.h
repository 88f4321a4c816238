#pragma once
// Rendering on a named device, shared by the `pathbench` command line and the
// benchmark binary (library target pathbench::run).
#include <string>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::app {

// Renders on the device named in the settings (CPU, or GPU where built).
void render_on_device(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, bool profile);
// Throws InputError when more than limits::kMaxDiscardedFraction of the render's
// samples were discarded (render_on_device calls it after every render).
void check_discarded(const Scene& scene, const RenderSettings& s, const RunReport& report);
// True when this build has the CUDA tracer and a device is present; otherwise sets
// *why_not (if given) to the reason.
bool gpu_available(std::string* why_not);

// The render time to report: CUDA-event time on the GPU, host wall clock on the CPU.
double render_seconds(const RunReport& r);
// The results/<machine>/ folder name for runs on `device`: the CPU's slug, or the
// GPU's (pb::gpu::DeviceInfo::slug) since the GPU sets a GPU run's numbers.
std::string machine_folder(Device device);

// Writes text to `path` through a temporary file and a rename.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace pb::app
