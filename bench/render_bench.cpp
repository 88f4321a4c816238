#include "render_bench.h"

#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <algorithm>
#include <fstream>

#include "pathbench/common/errors.h"
#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/run/energy.h"
#include "pathbench/run/built_scene.h"
#include "pathbench/run/run.h"
#include "bench_context.h"
#include "bench_ranks.h"
#include "scene_cache.h"

namespace pb::bench {

namespace {

// Resets this process's peak resident set (VmHWM) so the next render's peak is its
// own (Linux >= 4.0); harmless where unsupported.
void reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  if (f) f << "5";
}

// The energy meter's record as counters (render_bench.h); a missing figure's reason goes
// into the JSON's context instead (bench_context.h).
void add_energy_counters(benchmark::State& state, const std::string& name, nlohmann::json e, uint64_t rays,
                         uint64_t frames, double timed_seconds) {
  run::add_energy_rates(e, rays, frames);
  const double window = e.value("window_seconds", 0.0);
  if (e["joules"].is_number()) {
    state.counters["energy_joules_per_frame"] = e["joules_per_frame"].get<double>();
    if (e["rays_per_joule"].is_number()) state.counters["rays_per_joule"] = e["rays_per_joule"].get<double>();
    state.counters["average_watts"] = e["average_watts"].get<double>();
    state.counters["energy_window_seconds"] = window;
    state.counters["energy_busy_fraction"] = window > 0 ? timed_seconds / window : 0.0;
  } else {
    record_energy_unavailable(name, e.value("reason", std::string("unknown")));
  }
  if (e.contains("sm_clock_mhz")) {
    state.counters["sm_clock_mhz_mean"] = e["sm_clock_mhz"]["mean"].get<double>();
    state.counters["sm_clock_mhz_min"] = e["sm_clock_mhz"]["min"].get<double>();
  }
  if (e.contains("temperature_c")) state.counters["temperature_c_max"] = e["temperature_c"]["max"].get<double>();
  if (e.contains("throttle_reasons") && e["throttled"].is_boolean()) {
    state.counters["throttle_reasons"] = double(e["throttle_reasons"].get<uint64_t>());
    state.counters["throttled"] = e["throttled"].get<bool>() ? 1.0 : 0.0;
  }
}

uint64_t queue_bytes_of(const RunReport& r) {
  if (r.settings.strategy == Strategy::Pixel) return 0;
  // CPU wavefront: pool_bytes; GPU wavefront and paper-queue: pool_device_bytes.
  for (const char* key : {"queue_bytes", "pool_bytes", "pool_device_bytes"})
    if (r.extra.contains(key) && r.extra[key].is_number()) return r.extra[key].get<uint64_t>();
  return 0;
}

// The case's scene built once on its device (kept in the scene cache for the benchmark's
// repetitions); null where the case renders as other presets do, or under MPI ranks.
std::shared_ptr<const run::BuiltScene> prepared_scene(const RenderCase& c, const Scene& scene) {
  if (!c.build_once || bench_ranks() > 1) return nullptr;
  const RenderSettings& s = c.settings;
  const std::string kind = fmt::format("prepared:{}:{}:{}:{}", to_string(s.device), int(s.instancing),
                                       int(s.watertight), int(s.embree_layout));
  auto prep = std::static_pointer_cast<const run::BuiltScene>(cached_extra(c.scene, kind));
  if (!prep) {
    prep = std::make_shared<const run::BuiltScene>(scene, s);
    store_extra(c.scene, kind, std::const_pointer_cast<run::BuiltScene>(prep));
  }
  return prep;
}

void run_render(benchmark::State& state, const RenderCase& c) {
  const RenderSettings& s = c.settings;
  if (s.device == Device::Gpu) {
    std::string why;
    if (!run::gpu_available(&why)) {
      state.SkipWithError(("no GPU: " + why).c_str());
      return;
    }
  }
  std::shared_ptr<const Scene> scene;
  try {
    scene = cached_scene(c.scene);
  } catch (const InputError& e) {
    state.SkipWithError(fmt::format("scene not available: {}", e.what()).c_str());
    return;
  }
  std::shared_ptr<const run::BuiltScene> prepared;
  try {
    prepared = prepared_scene(c, *scene);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  Film film(s.width, s.height, false);
  uint64_t rays = 0, paths = 0;
  RunReport last;
  uint64_t peak_host = 0, peak_device = 0, tracer_host = 0;
  double cpu_seconds = 0, efficiency = 0, balance = 0;
  const std::string name = render_benchmark_name(c);
  const bool ranks = bench_ranks() > 1;
  run::RunOptions options;
  options.energy = false;  // measured over the whole loop below, not per frame
  double timed_seconds = 0;
  uint64_t frames = 0;
  run::EnergyMeter meter(s.device);
  for (auto _ : state) {
    reset_peak_rss();
    RunReport r;
    try {
      // Over MPI ranks: one frame of every rank, timed from their common start to the
      // film reduced on rank 0 (report.seconds, and device_seconds on GPUs).
      if (ranks) render_frame_over_ranks(name, *scene, s, film, r);
      else if (prepared) prepared->render(s, film, r, options);
      else run::render(*scene, s, film, r, options);
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      break;
    }
    state.SetIterationTime(s.device == Device::Gpu ? r.device_seconds : r.seconds);
    timed_seconds += s.device == Device::Gpu ? r.device_seconds : r.seconds;
    ++frames;
    rays += r.rays.total();
    paths += r.paths;
    peak_host = std::max(peak_host, r.peak_host_bytes);
    peak_device = std::max(peak_device, r.peak_device_bytes);
    tracer_host = std::max(tracer_host, r.tracer_host_bytes);
    cpu_seconds += r.load.value("process_cpu_seconds", 0.0);
    if (ranks) {
      efficiency += r.extra["ranks"].value("parallel_efficiency", 0.0);
      balance += r.extra["ranks"].value("load_balance", 0.0);
    }
    last = r;
  }
  add_energy_counters(state, name, meter.stop(), rays, frames, timed_seconds);
  if (last.extra.contains("film_hash")) record_film_hash(name, last.extra["film_hash"].get<std::string>());
  using benchmark::Counter;
  state.counters["rays_per_second"] = Counter(double(rays), Counter::kIsRate);
  state.counters["paths_per_second"] = Counter(double(paths), Counter::kIsRate);
  state.counters["peak_host_bytes"] = double(peak_host);
  state.counters["tracer_host_bytes"] = double(tracer_host);
  state.counters["peak_device_bytes"] = double(peak_device);
  state.counters["state_bytes_per_path"] = double(last.state_bytes_per_path);
  state.counters["queue_bytes"] = double(queue_bytes_of(last));
  state.counters["paths_in_flight"] = double(last.paths_in_flight);
  state.counters["pixels_x_spp"] = double(s.total_samples());
  state.counters["triangles"] = double(scene->triangles.size());
  // Not "threads": Google Benchmark writes its own "threads" key in every row.
  state.counters["cpu_threads"] = double(last.threads);
  if (prepared) state.counters["build_seconds"] = prepared->build_seconds();
  // Process CPU time (every thread) per iteration, around the whole render call: beside
  // the wall time it tells a contended run (wall up, CPU flat) from a slower one.
  state.counters["process_cpu_seconds"] = Counter(cpu_seconds, Counter::kAvgIterations);
  if (ranks) {  // rank 0's report over all ranks (ranks_report.h); process_cpu_seconds is rank 0's own
    state.counters["ranks"] = double(bench_ranks());
    state.counters["parallel_efficiency"] = Counter(efficiency, Counter::kAvgIterations);
    state.counters["load_balance"] = Counter(balance, Counter::kAvgIterations);
  }
  // Which Embree layout the CPU traced (auto decides per scene and process) and which
  // instruction set its path step ran (--isa auto: the widest the CPU has): a change of
  // either between two runs shows here, not only as a change of speed.
  if (last.extra.contains("embree_layout"))
    state.SetLabel("embree_layout=" + last.extra["embree_layout"]["used"].get<std::string>() +
                   (last.extra.contains("isa") ? " isa=" + last.extra["isa"].get<std::string>() : ""));
}

}  // namespace

std::string render_benchmark_name(const RenderCase& c) {
  if (!c.name.empty()) return c.name;
  const RenderSettings& s = c.settings;
  return fmt::format("render/{}/{}/{}/{}x{}/spp:{}/bounces:{}/{}", to_string(s.device), to_string(s.strategy), c.scene,
                     s.width, s.height, s.spp, s.max_bounces < 0 ? std::string("unbounded") : std::to_string(s.max_bounces),
                     to_string(s.sampling));
}

void register_render_benchmark(const RenderCase& c) {
  RenderCase copy = c;
  copy.settings.progress = false;
  remember_render_case(render_benchmark_name(copy), copy);
  auto* b = benchmark::RegisterBenchmark(render_benchmark_name(copy).c_str(),
                                         [copy](benchmark::State& st) { run_render(st, copy); });
  b->UseManualTime()->Unit(benchmark::kMillisecond);
  if (copy.iterations > 0) b->Iterations(copy.iterations);
}

}  // namespace pb::bench
