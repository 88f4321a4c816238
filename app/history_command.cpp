#include "history_command.h"

#include <fmt/core.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#ifndef PATHBENCH_SOURCE_DIR
#define PATHBENCH_SOURCE_DIR "."
#endif

namespace pb::app {

namespace fs = std::filesystem;

int run_history(int argc, char** argv, const char* module) {
  // The tool lives in the source tree (tools/history), run by the tree's .venv when it exists
  // (it has Otava and matplotlib); PATHBENCH_PYTHON overrides, python3 is the last resort.
  const fs::path src(PATHBENCH_SOURCE_DIR);
  std::string python = "python3";
  if (const char* env = std::getenv("PATHBENCH_PYTHON"); env && *env) {
    python = env;
  } else if (fs::exists(src / ".venv" / "bin" / "python")) {
    python = (src / ".venv" / "bin" / "python").string();
  }
  std::string path = (src / "tools").string();
  if (const char* old = std::getenv("PYTHONPATH"); old && *old) path += std::string(":") + old;
  setenv("PYTHONPATH", path.c_str(), 1);

  std::vector<char*> args{python.data(), const_cast<char*>("-m"), const_cast<char*>(module)};
  for (int i = 0; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execvp(args[0], args.data());
  fmt::print(stderr, "pathbench: error: {}: cannot run {}: {}\n", module, python, std::strerror(errno));
  return 2;
}

}  // namespace pb::app
