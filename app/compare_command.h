#pragma once
// `pathbench compare BASE.json NEW.json`: the command line of the benchmark judge
// (pathbench/analysis/bench_compare.h). Exit status: 0 no regression, 1 some benchmark
// regressed, 2 bad input (or --strict and the runs differ).
#include <CLI/CLI.hpp>

#include "pathbench/analysis/bench_compare.h"

namespace pb::app {

using analysis::CompareOptions;
using analysis::run_compare;
void add_compare_options(CLI::App& cmd, CompareOptions& o);

}  // namespace pb::app
