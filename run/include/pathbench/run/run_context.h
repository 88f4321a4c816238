#pragma once
// What a run records about where and under what load it ran: the machine fingerprint
// with the tracers' own sections, and the load around a render. run::render fills
// report.fingerprint and report.load with these; the benchmark binary (bench/) and
// `pathbench accuracy` call them for their own documents.
#include <nlohmann/json.hpp>

namespace pb::run {

// This process's machine fingerprint (pb::machine_fingerprint) with Embree's and TBB's
// facts and, when `with_gpu`, the GPU's (or why there is none).
nlohmann::json run_fingerprint(bool with_gpu);
// A sample of load average, process CPU time and wall clock, and the difference of two
// (load_average_at_start/_at_end, process_cpu_seconds, wall_seconds, cpu_per_wall).
nlohmann::json load_sample();
nlohmann::json load_between(const nlohmann::json& start, const nlohmann::json& end);

}  // namespace pb::run
