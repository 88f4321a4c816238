#include "suite_command.h"

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "python_tools.h"

namespace pb::app {

// tools/suite (Python's argparse takes the arguments) through the one Python launcher.
int run_suite(int argc, char** argv) {
  // The orchestrator runs pathbench-bench and pathbench from this build.
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec && !std::getenv("PATHBENCH_EXE")) setenv("PATHBENCH_EXE", self.c_str(), 1);
  return run_python_tool({"suite", "suite", {}}, std::vector<std::string>(argv, argv + argc));
}

}  // namespace pb::app
