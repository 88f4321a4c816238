#pragma once
// The environment every benchmark JSON carries. Before the run, as Google Benchmark
// custom context (strings): preset, CPU model and threads, GPU, compiler and flags, git
// revision, date, load. After the run, finish_benchmark_json rewrites the output file
// as strict JSON (no NaN/Infinity, no duplicate keys) and adds what only an object or
// the end of the run can give: context.fingerprint (pathbench/common/fingerprint.h),
// context.machine_id, context.load_average_at_end and context.run (process CPU time
// against wall time of the whole run).
#include <string>

namespace pb::bench {

void add_environment_context(const std::string& preset);
// Rewrites `path` (Google Benchmark's --benchmark_out JSON) as described above.
// Throws std::runtime_error when the file cannot be read back or written.
void finish_benchmark_json(const std::string& path);

}  // namespace pb::bench
