#pragma once
// Judging benchmark runs (`pathbench compare BASE.json NEW.json`, app/compare_command.h):
// two Google Benchmark JSON files, each
// with >= 9 repetitions per benchmark, by a two-sided Mann-Whitney U test on the
// repetition times plus a minimum effect size, and checks that the two runs can be
// compared at all (analysis/src/compare_context.h: machine, build, settings, Embree layout, load).
// A benchmark whose wall time regressed while its process CPU time stayed flat is
// "contended" (another process took the cores), not a regression. Exit status: 0 no
// regression, 1 some benchmark regressed, 2 bad input (no benchmark in common, every
// time zero, or --strict and the runs differ).
#include <nlohmann/json.hpp>

#include <map>
#include <set>
#include <string>
#include <vector>

namespace pb::analysis {

struct CompareOptions {
  std::string base, next;
  double threshold = 0.05;   // minimum relative slowdown of the median time
  double alpha = 0.05;       // significance level of the U test
  int min_repetitions = 9;
  bool quiet = false;        // only the verdict line
  bool strict = false;       // refuse (exit 2) when the runs differ in machine, build, settings, layout or load
  std::string format = "text";  // text | json | markdown
};

// Prints the table to stdout; returns 0 or 1. Throws InputError on bad input.
int run_compare(const CompareOptions& o);

// Two-sided Mann-Whitney U test of samples a and b. Exact null distribution when
// there are no ties and both samples are small; otherwise the normal approximation
// with tie and continuity corrections.
struct MannWhitneyResult {
  double u_a = 0;     // U statistic of a: pairs (a_i, b_j) with a_i > b_j, ties count 1/2
  double p = 1;       // two-sided p-value
  bool exact = false;
};
MannWhitneyResult mann_whitney_u(const std::vector<double>& a, const std::vector<double>& b);

double median(std::vector<double> v);

// One benchmark's repetitions, read from a Google Benchmark JSON file.
struct BenchSeries {
  std::vector<double> seconds;          // real (or manual) time per iteration, per repetition
  std::vector<double> rays_per_second;  // empty when the benchmark has no such counter
  // Process CPU seconds per iteration, per repetition: the process_cpu_seconds counter
  // (every thread), else Google Benchmark's cpu_time (its main thread only).
  std::vector<double> cpu_seconds;
  bool cpu_is_process = false;          // from process_cpu_seconds
  std::set<std::string> labels;         // e.g. "embree_layout=quads"
  double cpu_threads = -1;              // the cpu_threads (or older threads) counter; -1: none
  bool throttled = false;               // a repetition's "throttled" counter was 1 (GPU clocks lowered)
  bool error = false;
  std::string error_message;
};
// What compare reads of a file's "context" (analysis/src/compare_context.cpp), read
// once when the file is read with every field's type and range checked: a field of the
// wrong type is bad input naming the file and the field, never a failure later.
struct BenchContext {
  std::string git_revision = "unknown", date = "?", machine = "?";
  bool has_fingerprint = false;           // context.fingerprint (pathbench's machine fingerprint)
  std::string machine_id;                 // its machine_id: required in a fingerprint
  nlohmann::json identity;                // its {cpu, memory_gib}, to say how machines differ
  nlohmann::json build;                   // its {build, libraries}
  nlohmann::json gpu_id;                  // its gpu.gpu_id (null: no GPU)
  std::string gpu_name = "none";          // its gpu.name, else gpu.none
  nlohmann::json gb_machine;              // Google Benchmark's CPU facts (files without a fingerprint)
  nlohmann::json gb_build;                // compiler, cxx_flags, build_type, embree_version
  nlohmann::json settings;                // pathbench_preset, cpu_tbb_threads
  nlohmann::json load_avg;                // load_avg as given (null: none)
  double load1 = -1;                      // load_avg[0]; -1: not given
  double cpu_per_wall = -1;               // run.cpu_per_wall; -1: not given
  double num_cpus = -1;                   // num_cpus; -1: not given
};

// Keyed by run name, in file order of first appearance (second: order index).
struct BenchFile {
  std::string path;
  std::map<std::string, BenchSeries> series;
  std::vector<std::string> order;
  nlohmann::json context;               // the file's "context" object
  BenchContext run;                     // what compare reads of it, checked
};
// Google Benchmark JSON text parsed with its bare NaN / inf values read as null, keys
// in file order. Throws InputError naming `path` when it is not JSON.
nlohmann::ordered_json parse_benchmark_json_text(const std::string& raw, const std::string& path);
// The file as JSON, with Google Benchmark's bare NaN / inf values read as null.
// Throws InputError when it is missing or not JSON.
nlohmann::json read_benchmark_json(const std::string& path);
// The same for text already read (`path` names it in messages).
nlohmann::json parse_benchmark_json(const std::string& path, const std::string& text);
// Throws InputError: missing or unreadable file, not Google Benchmark JSON, or a
// benchmark with fewer than `min_repetitions` repetitions.
BenchFile load_benchmark_json(const std::string& path, int min_repetitions);
BenchFile bench_file_from_json(const std::string& path, const nlohmann::json& j, int min_repetitions);

// Contended: wall time regressed, process CPU time did not (another process had the
// cores). Invalid: a median time of zero, which measures nothing.
enum class Verdict { Same, Regressed, Improved, Contended, Invalid, Error, OnlyBase, OnlyNew };
const char* to_string(Verdict v);

struct CompareRow {
  std::string name;
  Verdict verdict = Verdict::Same;
  double base_median_s = 0, new_median_s = 0;
  double time_change = 0;        // new / base - 1 (positive: slower)
  bool has_rays = false;
  double rays_change = 0;        // new / base - 1 of the median rays/s (positive: faster)
  bool has_cpu = false;
  double base_cpu_s = 0, new_cpu_s = 0;  // median CPU seconds per iteration
  double cpu_change = 0;         // new / base - 1 of the median CPU time
  bool diverges = false;         // wall and CPU time moved apart by more than the threshold
  MannWhitneyResult test;
  std::string note;
};
std::vector<CompareRow> compare_files(const BenchFile& base, const BenchFile& next, double threshold, double alpha);

// What the report says besides the rows: the runs' revisions and machines, and the
// warnings about what differs between them (analysis/src/compare_context.h).
struct CompareReport {
  std::string base_path, new_path;
  nlohmann::json base_run, new_run;   // {"git_revision", "machine_id", "machine", "date"}
  std::vector<std::string> warnings;  // differences that make the comparison doubtful
  std::vector<std::string> notes;     // facts worth showing that are not differences
  std::vector<CompareRow> rows;
  double threshold = 0.05, alpha = 0.05;
};
int count_verdict(const std::vector<CompareRow>& rows, Verdict v);
// Formats (compare_format.cpp).
std::string format_table(const std::vector<CompareRow>& rows, double threshold, double alpha);
std::string format_text(const CompareReport& r);
std::string format_markdown(const CompareReport& r);
nlohmann::json format_json(const CompareReport& r);

}  // namespace pb::analysis
