#pragma once
// `pathbench reproduce`: the 2015 paper's experiment, on the CPU and (where there is
// one) the GPU, printed beside the paper's own figures.
#include <CLI/CLI.hpp>

#include <string>

namespace pb::app {

struct ReproduceOptions {
  std::string device = "all";   // cpu, gpu or all (= cpu, plus gpu when present)
  std::string out_dir;          // default results/<machine>
  uint32_t spp = 800;
  int threads = 0;
  bool quiet = false;
};

void add_reproduce_options(CLI::App& cmd, ReproduceOptions& o);
int run_reproduce(const ReproduceOptions& o);

}  // namespace pb::app
