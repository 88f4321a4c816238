#pragma once
// The run layer: the only place that turns settings into a finished film and report.
// It validates the settings once, checks the device once, sizes and begins the film,
// hands the tracer (cpu/ or gpu/) only what it traces, and fills the report fields
// common to both devices. The command line (app/), the benchmarks (bench/) and the
// Python module (python/) call it; the tracers never validate, size or begin a film.
//
// Ranks (MPI, later): a rank renders its share of every pixel's samples (ranks.h:
// share_of), its film begun for the whole frame's spp so that every rank's fixed-point
// scale is the same, and the integer sums are reduced exactly (reduce_film). Tracers
// never learn about ranks.
#include <string>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::run {

// How MPI ranks share a frame's samples (ranks_render.h): Auto = Static where every rank
// runs the same device kind, Dynamic (chunks from a shared counter) where they differ.
enum class Balance { Auto, Static, Dynamic };

struct RunOptions {
  bool profile = false;        // GPU: per-stage table on stdout and in report.extra["profile"]
  bool keep_variance = false;  // keep the variance sums even where settings.variance is off
  Balance balance = Balance::Auto;  // MPI ranks only
  bool energy = true;  // energy and clocks around the tracer into report.extra["energy"] (energy.h)
};

// Renders `scene` on settings.device into `film`, which is (re)sized to the settings
// (keeping its buffers when the size already matches) and begun; `report` is filled.
// Throws InputError for settings no tracer can run, no usable device, or a request the
// device's memory cannot hold.
void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report,
            const RunOptions& options = {});

// Throws InputError when more than limits::kMaxDiscardedFraction of the render's
// samples were discarded (render calls it after every render, so no such film is written).
void check_discarded(const Scene& scene, const RenderSettings& s, const RunReport& report);

struct Rendered {
  Film film;
  RunReport report;
};
Rendered render(const Scene& scene, const RenderSettings& settings, const RunOptions& options = {});

// True when this build has the CUDA tracer and a device is present; otherwise sets
// *why_not (if given) to the reason. Checked once per process.
bool gpu_available(std::string* why_not = nullptr);

// The render time to report: CUDA-event time on the GPU, host wall clock on the CPU.
double render_seconds(const RunReport& r);
// The results/<machine>/ folder name for runs on `device`: the CPU's slug, or the GPU's
// (pb::gpu::DeviceInfo::slug), since the GPU sets a GPU run's numbers.
std::string machine_folder(Device device);

}  // namespace pb::run
