#include "suite_command.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "history_command.h"

namespace pb::app {

int run_suite(int argc, char** argv) {
  // The orchestrator runs pathbench-bench and pathbench from this build.
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec && !std::getenv("PATHBENCH_EXE")) setenv("PATHBENCH_EXE", self.c_str(), 1);
  return run_history(argc, argv, "suite");
}

}  // namespace pb::app
