#include "bench_command.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "pathbench/common/errors.h"

namespace pb::app {

void add_bench_options(CLI::App& cmd, BenchOptions& o) {
  cmd.add_option("--preset", o.preset,
                 "quick (smoke), paper (the 2015 experiment), scaling or materials (diffuse-only vs mixed scenes)")
      ->capture_default_str();
  cmd.add_option("--out", o.out, "benchmark JSON to write (--benchmark_out)");
  cmd.add_option("--repetitions", o.repetitions, "repetitions per benchmark (regression runs: 9; aggregates and "
                                                 "every repetition are written)");
  cmd.allow_extras();  // --benchmark_* options go to Google Benchmark as they are
  cmd.footer("Other options (--benchmark_filter=..., --benchmark_min_time=...) are passed to pathbench-bench.");
}

int run_bench(const BenchOptions& o, const std::vector<std::string>& passthrough) {
  if (o.preset != "quick" && o.preset != "paper" && o.preset != "scaling" && o.preset != "materials")
    throw InputError(
        fmt::format("--preset: unknown preset '{}' (expected quick, paper, scaling or materials)", o.preset));
  if (o.repetitions < 0) throw InputError("--repetitions: must be >= 0");
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path bin = (ec ? std::filesystem::path(".") : self.parent_path()) / "pathbench-bench";
  if (!std::filesystem::exists(bin))
    throw InputError(fmt::format("{}: not found (build the target pathbench-bench; it needs Google Benchmark)",
                                 bin.string()));
  std::vector<std::string> args = {bin.string(), "--preset", o.preset};
  if (!o.out.empty()) {
    args.push_back("--benchmark_out=" + o.out);
    args.push_back("--benchmark_out_format=json");
  }
  if (o.repetitions > 0) {
    args.push_back(fmt::format("--benchmark_repetitions={}", o.repetitions));
    args.push_back("--benchmark_report_aggregates_only=false");
  }
  args.insert(args.end(), passthrough.begin(), passthrough.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(bin.c_str(), argv.data());
  throw std::runtime_error(fmt::format("{}: cannot run: {}", bin.string(), std::strerror(errno)));
}

}  // namespace pb::app
