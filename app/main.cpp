// pathbench: command line entry. Subcommands live in their own files.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include <algorithm>
#include <exception>
#include <string>
#include <string_view>

#include "accuracy_command.h"
#include "bench_command.h"
#include "compare_command.h"
#include "crosscheck_command.h"
#include "history_command.h"
#include "pathbench/common/display_text.h"
#include "pathbench/common/errors.h"
#include "pathbench/output/output_file.h"
#include "pathbench/run/world.h"
#include "render_command.h"
#include "reproduce_command.h"
#include "suite_command.h"
#include "version.h"

int main(int argc, char** argv) {
  // `history` takes its own arguments (Python's argparse), so it is handed over before CLI11 parses.
  if (argc >= 2 && std::string_view(argv[1]) == "history") return pb::app::run_history(argc - 2, argv + 2);
  if (argc >= 2 && std::string_view(argv[1]) == "suite") return pb::app::run_suite(argc - 2, argv + 2);
  CLI::App app{"pathbench: CPU/GPU path-tracing benchmark suite"};
  app.require_subcommand(1);
  app.set_version_flag("--version", [] {
    std::string text = pb::app::version_text();
    text.pop_back();  // CLI11 adds the last newline
    return text;
  }, "print the version, git revision and build flags");
  pb::app::RenderOptions render;
  auto* render_cmd = app.add_subcommand("render", "render one image and write its run report");
  pb::app::add_render_options(*render_cmd, render);
  pb::app::ReproduceOptions reproduce;
  auto* reproduce_cmd = app.add_subcommand("reproduce", "run the 2015 paper's experiment and print the table");
  pb::app::add_reproduce_options(*reproduce_cmd, reproduce);
  pb::app::BenchOptions bench;
  auto* bench_cmd = app.add_subcommand("bench", "run the Google Benchmark harness (pathbench-bench) with a preset");
  pb::app::add_bench_options(*bench_cmd, bench);
  pb::app::AccuracyOptions accuracy;
  auto* accuracy_cmd = app.add_subcommand(
      "accuracy", "measure the speed/accuracy trade: error against a converged reference, per configuration and spp");
  pb::app::add_accuracy_options(*accuracy_cmd, accuracy);
  // Listed for --help only: main() hands `history` over to tools/history before parsing.
  app.add_subcommand("history", "performance history: record runs, change points, dashboard, backfill (tools/history)");
  app.add_subcommand("suite", "run the workload suite on every device, record it, write one page (tools/suite)");
  pb::app::CrosscheckOptions crosscheck;
  auto* crosscheck_cmd = app.add_subcommand(
      "crosscheck", "render a scene with pathbench and Mitsuba 3 and judge them per pixel (same up to noise?)");
  pb::app::add_crosscheck_options(*crosscheck_cmd, crosscheck);
  pb::app::CompareOptions compare;
  auto* compare_cmd = app.add_subcommand("compare", "judge two benchmark JSON files for regressions (Mann-Whitney U)");
  pb::app::add_compare_options(*compare_cmd, compare);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line with the same prefix as every other user error (CLI11's own print is
    // two lines without it). Multi-line messages are joined.
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    fmt::print(stderr, "pathbench: error: {}\n", pb::terminal_safe(message));
    return pb::kExitBadInput;
  }
  // From here on output files are being written: a fatal signal removes their
  // temporary files (exit by the signal, 128 + its number in the shell).
  pb::install_output_signal_cleanup();
  // MPI ranks (run/world.h): the run ends on every rank through World::end, which
  // finalizes MPI or, for a failure only this rank knows of, aborts every rank.
  return pb::run::World::end([&] {
  try {
    if (render_cmd->parsed()) return pb::app::run_render(render);
    if (reproduce_cmd->parsed()) return pb::app::run_reproduce(reproduce);
    if (compare_cmd->parsed()) return pb::app::run_compare(compare);
    if (accuracy_cmd->parsed()) return pb::app::run_accuracy(accuracy);
    if (crosscheck_cmd->parsed()) return pb::app::run_crosscheck(crosscheck);
    if (bench_cmd->parsed()) return pb::app::run_bench(bench, bench_cmd->remaining());
  } catch (const pb::run::PeerFailure& e) {
    return e.code;  // another rank failed; rank 0 printed its message
  } catch (const pb::InputError& e) {
    fmt::print(stderr, "pathbench: error: {}\n", pb::terminal_safe(e.what()));  // names in it are data
    return pb::kExitBadInput;
  } catch (const std::exception& e) {
    fmt::print(stderr, "pathbench: failed: {}\n", pb::terminal_safe(e.what()));
    return pb::kExitFailed;
  }
  return 0;
  }());
}
