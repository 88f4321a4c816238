#pragma once
// Rendering on a named device, shared by the `pathbench` command line and the
// benchmark binary (library target pathbench::run).
#include <string>

#include <nlohmann/json.hpp>

#include "pathbench/common/film.h"
#include "pathbench/common/output_file.h"  // write_text_file, for the commands
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::app {

// Renders on the device named in the settings (CPU, or GPU where built); fills the
// report's fingerprint and its load (load average, process CPU and wall time around
// the render, so that a contended run can be told from a slow one).
void render_on_device(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, bool profile);
// Throws InputError when more than limits::kMaxDiscardedFraction of the render's
// samples were discarded (render_on_device calls it after every render).
void check_discarded(const Scene& scene, const RenderSettings& s, const RunReport& report);
// True when this build has the CUDA tracer and a device is present; otherwise sets
// *why_not (if given) to the reason.
bool gpu_available(std::string* why_not);

// This process's machine fingerprint (pb::machine_fingerprint) with Embree's and TBB's
// facts and, when `with_gpu`, the GPU's (or why there is none).
nlohmann::json run_fingerprint(bool with_gpu);
// A sample of load average, process CPU time and wall clock, and the difference of two
// (load_average_at_start/_at_end, process_cpu_seconds, wall_seconds, cpu_per_wall).
nlohmann::json load_sample();
nlohmann::json load_between(const nlohmann::json& start, const nlohmann::json& end);

// The render time to report: CUDA-event time on the GPU, host wall clock on the CPU.
double render_seconds(const RunReport& r);
// The results/<machine>/ folder name for runs on `device`: the CPU's slug, or the
// GPU's (pb::gpu::DeviceInfo::slug) since the GPU sets a GPU run's numbers.
std::string machine_folder(Device device);

}  // namespace pb::app
