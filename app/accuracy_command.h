#pragma once
// `pathbench accuracy`: the speed/accuracy trade, measured. Renders (or loads) a
// converged reference of a scene, then sweeps configurations -- bounce budget,
// sampling, Russian roulette, float/double, watertight/Moeller-Trumbore -- each at a
// ladder of spp (1, 4, 16, ... until a time cap), and records per render the seconds,
// rays, RMSE, relative MSE, bias against the reference with its standard error, and
// efficiency 1 / (relMSE x time). Writes <out-dir>/<scene>-<W>x<H>-<device>.json, then
// runs tools/accuracy_report.py (FLIP, the Markdown table, the plots) when the
// project's .venv is there.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

namespace pb::app {

struct AccuracyOptions {
  std::string scene = "paper-cornell";
  std::string device = "cpu", strategy = "pixel";
  uint32_t width = 128, height = 128;
  uint32_t reference_spp = 16384;
  uint32_t max_spp = 4096;    // the ladder's last rung at most
  double max_seconds = 20;    // a configuration's ladder stops before a render expected to take longer
  std::string configs;        // comma-separated configuration names; empty: all
  std::string out_dir;        // default pathbench-out/<machine>/accuracy (results/... with update_committed)
  bool update_committed = false;
  uint64_t seed = 1;
  int threads = 0;
  bool quick = false;         // tiny sizes for a smoke test
  bool regenerate_reference = false;
  bool no_report_tool = false;
};

void add_accuracy_options(CLI::App& cmd, AccuracyOptions& o);
int run_accuracy(AccuracyOptions& o);

}  // namespace pb::app
