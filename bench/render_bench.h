#pragma once
// Render benchmarks: one full render per iteration through pb::run::render,
// named render/<device>/<strategy>/<scene>/<W>x<H>/spp:<N>/bounces:<B>/<sampling>.
//
// Time is manual: the RunReport's render time (CPU: host clock around the render,
// after the Embree build; GPU: CUDA events, RunReport.device_seconds), so rays/s
// here is the RunReport's rays/s. Counters:
//   rays_per_second, paths_per_second   rates over all rays / paths traced (kIsRate)
//   peak_host_bytes     process peak resident set during the render (VmHWM, reset
//                       before each iteration; includes the scene and the program)
//   tracer_host_bytes   what the tracer allocated itself: film, path pool, BVH
//   peak_device_bytes   GPU memory at its peak (0 on the CPU)
//   state_bytes_per_path  bytes of path state per path (the paper: 48)
//   queue_bytes         bytes of the ray / path queue (wavefront pool, paper queue;
//                       0 for pixel-parallel)
//   pixels_x_spp, triangles, threads   the size of the job and where it ran
//   energy (pathbench/run/energy.h), measured over each repetition's whole loop of frames
//   (BVH builds between frames included; energy_busy_fraction = timed / window seconds):
//     energy_joules_per_frame, rays_per_joule, average_watts, energy_window_seconds,
//     energy_busy_fraction   where the device's counter is readable (else the reason is in
//                            the JSON's context.energy_unavailable); GPU also
//     sm_clock_mhz_mean, sm_clock_mhz_min, temperature_c_max, throttle_reasons (NVML's
//     clock-event mask, OR over the samples), throttled (1: clocks lowered by power/thermal)
//   build_seconds       build_once only: wall seconds of the one build (outside the frames)
#include <string>

#include "pathbench/common/settings.h"

namespace pb::bench {

struct RenderCase {
  std::string scene;
  RenderSettings settings;  // device, strategy, size, spp, bounces, sampling
  int iterations = 0;       // fixed iteration count; 0 = Google Benchmark decides. Each
                            // iteration rebuilds the BVH (untimed), so big scenes want few.
  std::string name;         // the benchmark's name; "" = render/<device>/... as below (the suite names its own)
  // The suite's cases (issue 28): the device's structure (Embree scene, GPU BVH) is built once
  // per benchmark (run::BuiltScene, kept for its repetitions) and every iteration renders a
  // frame on it, so the energy window holds frames only; the build's seconds are the counter
  // build_seconds. Other presets keep one full render (build included, untimed) per iteration.
  bool build_once = false;
};

std::string render_benchmark_name(const RenderCase& c);
void register_render_benchmark(const RenderCase& c);

}  // namespace pb::bench
