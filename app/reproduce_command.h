#pragma once
// `pathbench reproduce`: the 2015 paper's experiment (paper-cornell, 256x256, 800 spp,
// 2 bounces; uniform sampling as the paper did, and light sampling) on the CPU and,
// where there is one, the GPU, every strategy, printed beside the paper's own figures.
// Writes pathbench-out/<machine>/ (results/<machine>/ with --update-committed): paper-cornell.md (the table), paper-cornell-report.json
// (one RunReport per row), paper-cornell.png / .exr and per-device images.
#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>

namespace pb::app {

struct ReproduceOptions {
  std::string device = "all";   // cpu, gpu or all (= cpu, plus gpu when present)
  std::string out_dir;          // default pathbench-out/<machine> (results/<machine> with update_committed)
  bool update_committed = false;
  uint32_t spp = 800;
  uint32_t uniform_spp = 0;     // spp of the CPU uniform rows; 0 = spp, or fewer if the budget needs it
  double budget_s = 100;        // seconds for the CPU rows; over it, all CPU rows but the image row
                                // (pixel, nee) run at fewer spp, scaled in the table; 0 = no budget
  int threads = 0;
  bool quiet = false;
};

void add_reproduce_options(CLI::App& cmd, ReproduceOptions& o);
int run_reproduce(const ReproduceOptions& o);

}  // namespace pb::app
