#include "history_command.h"

#include <string>
#include <vector>

#include "python_tools.h"

namespace pb::app {

// tools/history (Python's argparse takes the arguments) through the one Python launcher.
int run_history(int argc, char** argv) {
  return run_python_tool({"history", "history", {}}, std::vector<std::string>(argv, argv + argc));
}

}  // namespace pb::app
