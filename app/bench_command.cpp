#include "bench_command.h"

#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <vector>

#include "cli_checks.h"
#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/output/output_file.h"
#include "pathbench/run/world.h"

namespace pb::app {

namespace {

// Runs bin with argv as a child (fatal signals passed on to it) and returns its exit
// status, or 128 + the signal that ended it.
int run_child(const std::filesystem::path& bin, std::vector<char*>& argv) {
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(fmt::format("cannot start {}: {}", bin.string(), std::strerror(errno)));
  if (pid == 0) {
    ::execv(bin.c_str(), argv.data());
    fmt::print(stderr, "pathbench: failed: {}: cannot run: {}\n", bin.string(), std::strerror(errno));
    ::_exit(127);
  }
  forward_signals_to(pid);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  forward_signals_to(0);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// Google Benchmark does not check its writes: a full disk would leave a prefix.
void check_complete_json(OutputFile& out) {
  std::ifstream in(out.temp_path());
  if (!nlohmann::json::accept(in))
    throw InputError(fmt::format("--out {}: pathbench-bench wrote incomplete JSON (is the disk full?)",
                                 display_path(out.path())));
}

}  // namespace

void add_bench_options(CLI::App& cmd, BenchOptions& o) {
  cmd.add_option("--preset", o.preset,
                 "quick (smoke), paper (the 2015 experiment), scaling or materials (diffuse-only vs mixed scenes)")
      ->capture_default_str();
  cmd.add_option("--out", o.out, "benchmark JSON to write (--benchmark_out)");
  cmd.add_option("--repetitions", o.repetitions, "repetitions per benchmark (regression runs: 9; aggregates and "
                                                 "every repetition are written)")
      ->check(non_negative());
  cmd.allow_extras();  // --benchmark_* options go to Google Benchmark as they are
  cmd.footer("Other options (--benchmark_filter=..., --benchmark_min_time=...) are passed to pathbench-bench.");
}

int run_bench(const BenchOptions& o, const std::vector<std::string>& passthrough) {
  if (o.preset != "quick" && o.preset != "paper" && o.preset != "scaling" && o.preset != "materials")
    throw InputError(
        fmt::format("--preset: unknown preset '{}' (expected quick, paper, scaling or materials)", o.preset));
  if (o.repetitions < 0) throw InputError("--repetitions: must be >= 0");
  // --out goes to a temporary file in the target folder (Google Benchmark writes it
  // unchecked, in place); it is renamed into place only when pathbench-bench
  // succeeded and the file holds complete JSON. So this runs it as a child.
  std::optional<OutputFile> out;
  // Under mpirun each rank's `pathbench bench` starts a pathbench-bench that joins the
  // run as that rank (bench/bench_ranks.h); only rank 0's writes results.
  if (!o.out.empty() && run::launcher_rank() <= 0) {
    if (image_extension(o.out) != ".json")
      throw InputError(fmt::format("--out {}: the benchmark results are JSON; name it .json", display_path(o.out)));
    check_output_path(o.out, "--out");
    out.emplace(o.out);
  }
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path bin = (ec ? std::filesystem::path(".") : self.parent_path()) / "pathbench-bench";
  if (!std::filesystem::exists(bin))
    throw InputError(fmt::format("{}: not found (build the target pathbench-bench; it needs Google Benchmark)",
                                 bin.string()));
  std::vector<std::string> args = {bin.string(), "--preset", o.preset};
  if (out) {
    args.push_back("--benchmark_out=" + out->temp_path());
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
  if (!out) {
    ::execv(bin.c_str(), argv.data());
    throw std::runtime_error(fmt::format("{}: cannot run: {}", bin.string(), std::strerror(errno)));
  }
  const int status = run_child(bin, argv);
  if (status != 0) {
    // A truncated file (a full disk) also fails pathbench-bench's own strict-JSON
    // rewrite; say what happened rather than pass on its exit status 1.
    if (status < 128) check_complete_json(*out);
    return status;  // its message is on stderr; the temporary file goes
  }
  check_complete_json(*out);
  out->commit();
  return 0;
}

}  // namespace pb::app
