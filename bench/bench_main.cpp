// pathbench-bench: Google Benchmark harness for pathbench.
//
//   pathbench-bench --preset quick|paper|scaling|materials [--benchmark_* options]
//
//   quick    smoke run (< 1 min on 2 cores): paper-cornell 64x64, 4 spp, CPU pixel and
//            wavefront (and GPU where present), uniform and nee; Embree ray casts.
//   paper    the 2015 paper's experiment: paper-cornell 256x256, 800 spp, 2 bounces,
//            uniform (the paper's sampler) and nee, every strategy and device;
//            Embree ray casts on paper-cornell.
//   scaling  rays/s vs triangle count (scaling:N, N = 10 .. 10^7), time vs spp and
//            vs resolution (paper-cornell); Embree ray casts on every scaling:N.
//   materials  diffuse-only against mirror/glass/GGX scenes (materials_bench.h).
//   loading  scene-file loading time against placements, fitted to O(N) (loading_bench.h).
//   gpu-layouts  the GPU BVH layouts side by side (bvh_layout.h): raw ray casts in each
//            layout on paper-cornell, paper-cornell-ico:0/1/2 (34, 94, 334 triangles:
//            where brute force stops paying) and paper-cornell-ico:8 (1.31 M).
//
// Regression runs: --benchmark_repetitions=9 --benchmark_report_aggregates_only=false
// --benchmark_out=FILE.json, then `pathbench compare BASE.json FILE.json`. That file is
// strict JSON with the machine fingerprint (bench_context.h); so is the JSON on stdout
// (--benchmark_format=json), printed once the run has finished.
//
// Under mpirun (`mpirun -np N pathbench-bench ...`) each render benchmark iteration is
// one frame over the N ranks (bench_ranks.h).
#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <charconv>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_context.h"
#include "bench_ranks.h"
#include "pathbench/common/display_text.h"
#include "pathbench/common/errors.h"
#include "pathbench/run/world.h"
#if PATHBENCH_BENCH_GPU
#include "pathbench/bvh/bvh_layout.h"
#endif
#include "loading_bench.h"
#include "materials_bench.h"
#include "raycast_bench.h"
#include "render_bench.h"
#include "suite_bench.h"

namespace pb::bench {
namespace {

std::vector<Device> devices() {
  std::vector<Device> d = {Device::Cpu};
#if PATHBENCH_BENCH_GPU
  d.push_back(Device::Gpu);  // skipped at run time (SkipWithError) without a device
#endif
  return d;
}

std::vector<Strategy> strategies(Device d) {
  if (d == Device::Cpu) return {Strategy::Pixel, Strategy::Wavefront};
  return {Strategy::Pixel, Strategy::Wavefront, Strategy::PaperQueue};
}

RenderCase render_case(const std::string& scene, Device dev, Strategy strat, uint32_t w, uint32_t h, uint32_t spp,
                       int bounces, Sampling sampling) {
  RenderCase c;
  c.scene = scene;
  c.settings.device = dev;
  c.settings.strategy = strat;
  c.settings.width = w;
  c.settings.height = h;
  c.settings.spp = spp;
  c.settings.max_bounces = bounces;
  c.settings.sampling = sampling;
  return c;
}

// paper-cornell at the paper's two bounces, uniform (the paper's sampler) and nee,
// every device and strategy; then Embree's ray casts on the same scene.
void register_paper_cornell(uint32_t side, uint32_t spp, uint32_t raycast_side) {
  for (Device dev : devices())
    for (Sampling sampling : {Sampling::Uniform, Sampling::Nee})
      for (Strategy strat : strategies(dev))
        register_render_benchmark(render_case("paper-cornell", dev, strat, side, side, spp, 2, sampling));
  register_raycast_benchmarks({"paper-cornell", raycast_side, raycast_side});
#if PATHBENCH_BENCH_GPU
  register_gpu_raycast_benchmarks({"paper-cornell", raycast_side, raycast_side});
#endif
}

void preset_quick() { register_paper_cornell(64, 4, 128); }

void preset_paper() {
  register_paper_cornell(256, 800, 256);
#if PATHBENCH_BENCH_GPU
  // Issue 32's large-scene row: paper-cornell-ico:8 (1.31 M triangles), GPU megakernel, the
  // paper's frame with light sampling (the layout `auto` picks; bvh_layout.h).
  register_render_benchmark(render_case("paper-cornell-ico:8", Device::Gpu, Strategy::Pixel, 256, 256, 800, 2, Sampling::Nee));
#endif
}

// Largest scaling scene; 10^7 needs several GB and about a minute per build on 2 cores.
// PATHBENCH_SCALING_MAX lowers it: a whole number in the scaling:N scenes' range, else
// one line and exit 2 (strtoull took "abc" for 0, "-1" and 2^64-1 for a sweep that
// never ends: n *= 10 wraps).
constexpr uint64_t kScalingMin = 10, kScalingMax = 10000000;
uint64_t scaling_max_triangles() {
  const char* env = std::getenv("PATHBENCH_SCALING_MAX");
  if (!env) return kScalingMax;
  const std::string text = env;
  uint64_t n = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || n < kScalingMin || n > kScalingMax)
    throw InputError(fmt::format("PATHBENCH_SCALING_MAX='{}': expected a whole number of triangles from {} to {} "
                                 "(the scaling:N scenes' range)",
                                 terminal_safe(text), kScalingMin, kScalingMax));
  return n;
}

void preset_scaling() {
  // Rays/s vs triangle count: renders and raw ray casts per scene, grouped by scene
  // so each is built once. Smaller images for the largest scenes keep 2 cores sane.
  for (uint64_t n = 10; n <= scaling_max_triangles(); n *= 10) {
    const std::string scene = fmt::format("scaling:{}", n);
    const uint32_t side = n >= 1000000 ? 64 : 128;
    for (Device dev : devices())
      for (Strategy strat : strategies(dev)) {
        RenderCase c = render_case(scene, dev, strat, side, side, 8, 2, Sampling::Nee);
        // Every iteration builds the BVH again, outside the timed render: a fixed
        // count keeps 10^6..10^7 triangles from taking minutes.
        c.iterations = 3;
        register_render_benchmark(c);
      }
    register_raycast_benchmarks({scene, 256, 256});
  }
  // Time vs spp and vs resolution (and memory vs pixels x spp), paper-cornell, nee.
  for (Device dev : devices())
    for (Strategy strat : strategies(dev)) {
      for (uint32_t spp : {1u, 4u, 16u, 64u, 256u})
        register_render_benchmark(render_case("paper-cornell", dev, strat, 128, 128, spp, 2, Sampling::Nee));
      for (uint32_t side : {32u, 64u, 128u, 256u, 512u})
        if (side != 128)  // 128x128 at 16 spp is in the spp sweep
          register_render_benchmark(render_case("paper-cornell", dev, strat, side, side, 16, 2, Sampling::Nee));
    }
}

void preset_gpu_layouts() {
#if PATHBENCH_BENCH_GPU
  using bvh::GpuBvhLayout;
  for (const char* scene : {"paper-cornell", "paper-cornell-ico:0", "paper-cornell-ico:1", "paper-cornell-ico:2",
                            "paper-cornell-ico:8"})
    register_gpu_raycast_benchmarks({scene, 256, 256}, {GpuBvhLayout::Binary, GpuBvhLayout::Wide4, GpuBvhLayout::Wide8,
                                                        GpuBvhLayout::Brute, GpuBvhLayout::Leaves});
#else
  fmt::print(stderr, "pathbench-bench: --preset gpu-layouts needs a CUDA build (PATHBENCH_CUDA=ON)\n");
  std::exit(2);
#endif
}

}  // namespace
}  // namespace pb::bench

namespace {
int run_benchmarks(int argc, char** argv);
}

// Under mpirun every rank parses the same command line and registers the same
// benchmarks; rank 0 runs them, the others follow its frames (bench_ranks.h).
// World::end finalizes MPI (or aborts every rank for a failure only this one knows).
int main(int argc, char** argv) { return pb::run::World::end(run_benchmarks(argc, argv)); }

namespace {
int run_benchmarks(int argc, char** argv) {
  // --preset NAME / --preset=NAME, removed from argv before Google Benchmark sees it.
  std::string preset = "quick";
  std::string suite_cases;  // --suite-cases FILE (--preset suite, suite_bench.h)
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (i > 0 && std::strcmp(argv[i], "--suite-cases") == 0 && i + 1 < argc) {
      suite_cases = argv[++i];
      continue;
    }
    if (i > 0 && std::strcmp(argv[i], "--preset") == 0) {
      if (i + 1 >= argc) {
        fmt::print(stderr, "pathbench-bench: --preset needs a value (quick, paper, scaling or materials)\n");
        return 2;
      }
      preset = argv[++i];
      continue;
    }
    if (i > 0 && std::strncmp(argv[i], "--preset=", 9) == 0) {
      preset = argv[i] + 9;
      continue;
    }
    args.push_back(argv[i]);
  }
  if (preset == "quick") pb::bench::preset_quick();
  else if (preset == "paper") pb::bench::preset_paper();
  else if (preset == "scaling") {
    try {
      pb::bench::preset_scaling();
    } catch (const pb::InputError& e) {
      fmt::print(stderr, "pathbench-bench: {}\n", e.what());
      return 2;
    }
  }
  else if (preset == "materials") pb::bench::preset_materials();
  else if (preset == "gpu-layouts") pb::bench::preset_gpu_layouts();
  else if (preset == "loading") pb::bench::preset_loading();
  else if (preset == "suite") {
    try {
      preset = pb::bench::preset_suite(suite_cases);
    } catch (const std::exception& e) {
      fmt::print(stderr, "pathbench-bench: {}\n", e.what());
      return 2;
    }
  } else {
    fmt::print(stderr, "pathbench-bench: unknown --preset '{}' (expected quick, paper, scaling, materials, gpu-layouts, loading or suite)\n",
               preset);
    return 2;
  }
  // The output file (--benchmark_out=PATH, JSON unless another format is asked for) is
  // rewritten after the run as strict JSON with the fingerprint and the end-of-run load.
  // Read before Initialize, which removes the flags it knows from argv.
  std::string out_path, out_format = "json", display_format = "console";
  for (size_t i = 1; i < args.size(); ++i) {
    const std::string a = args[i];
    if (a.rfind("--benchmark_out=", 0) == 0) out_path = a.substr(16);
    if (a.rfind("--benchmark_out_format=", 0) == 0) out_format = a.substr(23);
    if (a.rfind("--benchmark_format=", 0) == 0) display_format = a.substr(19);
  }
  int new_argc = int(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&new_argc, args.data());
  if (benchmark::ReportUnrecognizedArguments(new_argc, args.data())) return 2;
  if (pb::bench::bench_follower()) return pb::bench::follow_rank0();
  pb::bench::add_environment_context(preset);
  // --benchmark_format=json: Google Benchmark's JSON reporter writes into a buffer,
  // printed after the run in the same strict form as the output file.
  std::ostringstream json_display;
  benchmark::JSONReporter json_reporter;
  if (display_format == "json") {
    json_reporter.SetOutputStream(&json_display);
    json_reporter.SetErrorStream(&std::cerr);
    benchmark::RunSpecifiedBenchmarks(&json_reporter);
  } else {
    benchmark::RunSpecifiedBenchmarks();
  }
  pb::bench::release_followers();
  benchmark::Shutdown();
  if (display_format == "json") {
    try {
      std::cout << pb::bench::strict_benchmark_json(json_display.str(), "stdout");
    } catch (const std::exception& e) {
      fmt::print(stderr, "pathbench-bench: {}\n", e.what());
      return 1;
    }
  }
  if (!out_path.empty() && out_format == "json") {
    try {
      pb::bench::finish_benchmark_json(out_path);
    } catch (const std::exception& e) {
      fmt::print(stderr, "pathbench-bench: {}\n", e.what());
      return 1;
    }
  }
  return 0;
}
}  // namespace
