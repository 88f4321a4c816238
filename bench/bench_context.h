#pragma once
// The environment every benchmark JSON carries. Before the run, as Google Benchmark
// custom context (strings): preset, CPU model and threads, GPU, compiler and flags, git
// revision, date, load. After the run, finish_benchmark_json rewrites the output file
// as strict JSON (no NaN/Infinity, no duplicate keys) and adds what only an object or
// the end of the run can give: context.fingerprint (pathbench/common/fingerprint.h),
// context.machine_id, context.load_average_at_end, context.run (process CPU time
// against wall time of the whole run) and the films' checksums: context.film_hashes
// (benchmark name -> run::film_hash of its last iteration's film) and context.film_hash
// (one hash over all of them, the history's per-run image checksum).
#include <string>

namespace pb::bench {

void add_environment_context(const std::string& preset);
// Rewrites `path` (Google Benchmark's --benchmark_out JSON) as described above.
// Throws std::runtime_error when the file cannot be read back or written.
void finish_benchmark_json(const std::string& path);
// The same rewrite of Google Benchmark JSON text (`where` names it in errors), for the
// JSON that --benchmark_format=json prints on stdout.
std::string strict_benchmark_json(const std::string& raw, const std::string& where);
// Called by each render benchmark with its film's run::film_hash.
void record_film_hash(const std::string& benchmark, const std::string& hash);
// Why a benchmark has no energy counters (NVML/RAPL unreadable, window too short):
// context.energy_unavailable (benchmark name -> reason).
void record_energy_unavailable(const std::string& benchmark, const std::string& reason);

}  // namespace pb::bench
