#pragma once
// Judging benchmark runs (`pathbench compare BASE.json NEW.json`, app/compare_command.h): two Google Benchmark JSON files, each
// with >= 9 repetitions per benchmark, by a two-sided Mann-Whitney U test on the
// repetition times plus a minimum effect size. Exit status: 0 no regression, 1 some
// benchmark regressed, 2 bad input.
#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace pb::analysis {

struct CompareOptions {
  std::string base, next;
  double threshold = 0.05;   // minimum relative slowdown of the median time
  double alpha = 0.05;       // significance level of the U test
  int min_repetitions = 9;
  bool quiet = false;        // only the verdict line
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
  bool error = false;
  std::string error_message;
};
// Keyed by run name, in file order of first appearance (second: order index).
struct BenchFile {
  std::string path;
  std::map<std::string, BenchSeries> series;
  std::vector<std::string> order;
};
// The file as JSON, with Google Benchmark's bare NaN / inf values read as null.
// Throws InputError when it is missing or not JSON.
nlohmann::json read_benchmark_json(const std::string& path);
// Throws InputError: missing or unreadable file, not Google Benchmark JSON, or a
// benchmark with fewer than `min_repetitions` repetitions.
BenchFile load_benchmark_json(const std::string& path, int min_repetitions);

enum class Verdict { Same, Regressed, Improved, Error, OnlyBase, OnlyNew };
const char* to_string(Verdict v);

struct CompareRow {
  std::string name;
  Verdict verdict = Verdict::Same;
  double base_median_s = 0, new_median_s = 0;
  double time_change = 0;        // new / base - 1 (positive: slower)
  bool has_rays = false;
  double rays_change = 0;        // new / base - 1 of the median rays/s (positive: faster)
  MannWhitneyResult test;
  std::string note;
};
std::vector<CompareRow> compare_files(const BenchFile& base, const BenchFile& next, double threshold, double alpha);
std::string format_table(const std::vector<CompareRow>& rows, double threshold, double alpha);

}  // namespace pb::analysis
