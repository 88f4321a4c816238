#pragma once
// `pathbench bench`: runs the benchmark binary (pathbench-bench, beside this one) with
// a preset and Google Benchmark's own options passed through.
#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace pb::app {

struct BenchOptions {
  std::string preset = "quick";
  std::string out;   // --benchmark_out=FILE (JSON)
  int repetitions = 0;
};

void add_bench_options(CLI::App& cmd, BenchOptions& o);
// Replaces this process with pathbench-bench (with --out: runs it as a child and
// renames the JSON into place only when it is complete); returns its exit status.
int run_bench(const BenchOptions& o, const std::vector<std::string>& passthrough);

}  // namespace pb::app
