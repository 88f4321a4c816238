#include "bench_context.h"

#include <benchmark/benchmark.h>
#include <embree3/rtcore_config.h>
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <fstream>

#include "pathbench/common/report.h"
#include "pathbench/cpu/isa.h"

#if PATHBENCH_BENCH_GPU
#include "pathbench/gpu/render.h"
#endif

namespace pb::bench {

namespace {

std::string first_line(const char* path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

std::string utc_now() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", tm);
}

void add(const char* key, const std::string& value) { benchmark::AddCustomContext(key, value); }

void add_gpu_context() {
#if PATHBENCH_BENCH_GPU
  std::string why;
  if (!gpu::device_available(&why)) {
    add("gpu", "none: " + why);
    return;
  }
  const gpu::DeviceInfo info = gpu::device_info();
  add("gpu_name", info.name);
  add("gpu_compute_capability", fmt::format("{}.{}", info.compute_major, info.compute_minor));
  add("gpu_multiprocessors", std::to_string(info.multiprocessors));
  add("gpu_memory_bytes", std::to_string(info.total_memory));
  add("cuda_driver_api", fmt::format("{}.{}", info.driver_version / 1000, (info.driver_version % 1000) / 10));
  add("cuda_runtime", fmt::format("{}.{}", info.runtime_version / 1000, (info.runtime_version % 1000) / 10));
  const std::string nv = first_line("/proc/driver/nvidia/version");  // the kernel driver's own version line
  add("gpu_driver", nv.empty() ? "unknown" : nv);
#else
  add("gpu", "none (built without the CUDA tracer)");
#endif
}

}  // namespace

void add_environment_context(const std::string& preset) {
  add("pathbench_preset", preset);
  add("cpu_model", cpu_model());
  add("cpu_hardware_threads", std::to_string(hardware_threads()));
  add("cpu_tbb_threads", std::to_string(tbb::this_task_arena::max_concurrency()));
  add("machine", machine_slug());
  add("compiler", fmt::format("{} ({})", PATHBENCH_BENCH_COMPILER, compiler_id()));
  add("cxx_flags", PATHBENCH_BENCH_CXX_FLAGS);
  add("build_type", PATHBENCH_BENCH_BUILD_TYPE);
  add("embree_version", RTC_VERSION_STRING);
  add("cpu_vector_flags", fmt::format("{}", fmt::join(cpu::cpu_vector_flags(), " ")));  // which --isa can run
  // A copy of the tree without .git (a GPU host) has no revision of its own; the
  // copier may name the source commit in PATHBENCH_SOURCE_COMMIT.
  std::string rev = git_revision();
  const char* source_commit = std::getenv("PATHBENCH_SOURCE_COMMIT");
  if ((rev.empty() || rev == "unknown") && source_commit && *source_commit)
    rev = std::string(source_commit) + " (PATHBENCH_SOURCE_COMMIT; the tree may have had uncommitted changes)";
  add("git_revision", rev.empty() ? "unknown" : rev);
  add("date_utc", utc_now());
  add("load_average_at_start", first_line("/proc/loadavg"));
  add_gpu_context();
}

}  // namespace pb::bench
