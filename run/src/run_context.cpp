#include "pathbench/run/run_context.h"

#include <chrono>
#include <string>

#include "pathbench/common/fingerprint.h"
#include "pathbench/cpu/embree_facts.h"
#include "pathbench/run/run.h"
#include "pathbench/run/tracer.h"

namespace pb::run {

nlohmann::json run_fingerprint(bool with_gpu) {
  nlohmann::json fp = machine_fingerprint();
  const nlohmann::json& et = cpu::embree_tbb_facts();
  fp["embree"] = et["embree"];
  fp["libraries"]["embree"] = et["embree"].value("version", et["embree"]["version_compiled"].get<std::string>());
  fp["libraries"]["tbb"] = et["tbb"]["version"];
  fp["tbb"] = et["tbb"];
  if (!with_gpu) return fp;
  std::string why;
  if (gpu_available(&why)) {
    static const nlohmann::json gpu_facts = gpu_tracer().fingerprint();  // NVML is opened once per process
    fp["gpu"] = gpu_facts;
    return fp;
  }
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

}  // namespace pb::run
