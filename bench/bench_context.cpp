#include "bench_context.h"
#include "bench_ranks.h"

#include <benchmark/benchmark.h>
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <ctime>
#include <fstream>
#include <iterator>
#include <map>
#include <stdexcept>

#include "pathbench/analysis/bench_compare.h"
#include "pathbench/common/fingerprint.h"
#include "pathbench/output/output_file.h"
#include "pathbench/common/report.h"
#include "pathbench/cpu/isa.h"
#include "pathbench/run/run_context.h"

namespace pb::bench {

namespace {

uint64_t fnv1a64(const std::string& text) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : text) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

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

// Fingerprint with the GPU's section where this build has the GPU tracer.
const nlohmann::json& fingerprint() {
  static const nlohmann::json fp = run::run_fingerprint(PATHBENCH_BENCH_GPU != 0);
  return fp;
}

nlohmann::json& run_start() {
  static nlohmann::json start;
  return start;
}

}  // namespace

void add_environment_context(const std::string& preset) {
  run_start() = run::load_sample();
  const nlohmann::json& fp = fingerprint();
  const nlohmann::json& build = fp["build"];
  add("pathbench_preset", preset);
  add("cpu_model", cpu_model());
  add("cpu_hardware_threads", std::to_string(hardware_threads()));
  add("cpu_tbb_threads", std::to_string(tbb::this_task_arena::max_concurrency()));
  add("machine", machine_slug());  // results/<machine>/ folder; the identity is machine_id
  // As before the fingerprint ("GNU 12.2.0 (gcc 12.2.0)"), so old and new files agree.
  add("compiler", fmt::format("{} ({})", build["cmake_compiler"].get<std::string>(), build["compiler"].get<std::string>()));
  add("cxx_flags", build["cxx_flags"].get<std::string>());
  add("build_type", build["build_type"].get<std::string>());
  add("embree_version", fp["libraries"]["embree"].get<std::string>());
  std::string rev = build["git_revision"].get<std::string>();
  if ((rev.empty() || rev == "unknown") && build.contains("source_commit"))
    rev = build["source_commit"].get<std::string>() + " (PATHBENCH_SOURCE_COMMIT; the tree may have had uncommitted changes)";
  add("cpu_vector_flags", fmt::format("{}", fmt::join(cpu::cpu_vector_flags(), " ")));  // which --isa can run
  add("git_revision", rev.empty() ? "unknown" : rev);
  add("date_utc", utc_now());
  add("load_average_at_start", first_line("/proc/loadavg"));
  // mpirun -np N: each render iteration is one frame over N ranks (bench_ranks.h); the
  // fingerprint and load are rank 0's host's.
  add("mpi_ranks", std::to_string(bench_ranks()));
  if (fp.contains("gpu") && fp["gpu"].contains("name")) {
    add("gpu_name", fp["gpu"]["name"].get<std::string>());
    add("gpu_driver", fp["gpu"]["driver"].get<std::string>());
    add("cuda_runtime", fp["gpu"]["cuda_runtime"].get<std::string>());
  } else {
    add("gpu", fp.contains("gpu") ? "none: " + fp["gpu"].value("none", std::string("?"))
                                  : std::string("none (built without the CUDA tracer)"));
  }
}

namespace {

// Benchmark name -> film hash, in name order (std::map) so the combined hash does not
// depend on the order the benchmarks ran in.
std::map<std::string, std::string>& film_hashes() {
  static std::map<std::string, std::string> hashes;
  return hashes;
}

}  // namespace

void record_film_hash(const std::string& benchmark, const std::string& hash) { film_hashes()[benchmark] = hash; }

namespace {
std::map<std::string, std::string>& energy_unavailable() {
  static std::map<std::string, std::string> reasons;
  return reasons;
}
}  // namespace

void record_energy_unavailable(const std::string& benchmark, const std::string& reason) {
  energy_unavailable()[benchmark] = reason;
}

std::string strict_benchmark_json(const std::string& raw, const std::string& where) {
  // Google Benchmark writes NaN for the cv of a counter that is always zero (0 / 0);
  // the tolerant parser reads it as null. Duplicate keys collapse on parsing (and no
  // counter of ours is named like one of Google Benchmark's keys).
  nlohmann::ordered_json doc = analysis::parse_benchmark_json_text(raw, where);
  const nlohmann::json end = run::load_sample();
  auto& ctx = doc["context"];
  ctx["machine_id"] = fingerprint()["machine_id"];
  ctx["fingerprint"] = nlohmann::ordered_json::parse(fingerprint().dump());
  ctx["load_average_at_end"] = first_line("/proc/loadavg");
  if (!run_start().is_null())
    ctx["run"] = nlohmann::ordered_json::parse(run::load_between(run_start(), end).dump());
  if (!film_hashes().empty()) {
    std::string all;
    for (const auto& [name, hash] : film_hashes()) all += name + "=" + hash + "\n";
    ctx["film_hash"] = fmt::format("fnv1a64:{:016x}", fnv1a64(all));
    ctx["film_hashes"] = film_hashes();
  }
  if (!energy_unavailable().empty()) ctx["energy_unavailable"] = energy_unavailable();
  return doc.dump(2) + "\n";
}

void finish_benchmark_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read the benchmark output back", path));
  const std::string raw((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  write_text_file(path, strict_benchmark_json(raw, path));
}

}  // namespace pb::bench
