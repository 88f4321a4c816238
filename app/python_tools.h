#pragma once
// The one launcher for the subcommands that run Python (history, accuracy's report,
// crosscheck, suite). It finds
//   - the interpreter: $PATHBENCH_PYTHON; else a python3 beside the executable (a venv that
//     `pip install .` filled); else the source tree's .venv (a build tree); else python3 on PATH;
//   - the tools: $PATHBENCH_TOOLS_DIR; else <exe>/../share/pathbench/tools (what
//     `cmake --install` and `pip install .` lay down); else the source tree's tools/ (a build tree);
// checks that the tool's Python dependencies import, then runs it with the tools on PYTHONPATH.
// Python or a dependency missing: one `pathbench: error:` line naming it and what to do, status 2.
#include <string>
#include <vector>

namespace pb::app {

struct PythonTool {
  std::string command;                // the subcommand, for messages ("history")
  std::string target;                 // a module run as -m ("history") or a script in the tools ("crosscheck.py");
                                      // "" only checks that Python, the tools and the modules are there
  std::vector<std::string> modules;   // modules that must import ("numpy", "mitsuba")
};

// Where the tools are, or "" when not found (`looked` gets the places tried).
std::string find_python_tools(std::string* looked = nullptr);
// The interpreter the launcher would use.
std::string find_python();

// Runs the tool and waits: its exit status (2 with one message line when Python, the tools
// or a dependency is missing). `quiet_if_missing`: no message then (the caller explains).
int run_python_tool(const PythonTool& tool, const std::vector<std::string>& args, bool quiet_if_missing = false);

// The status run_python_tool returns when it could not start the tool.
inline constexpr int kPythonToolMissing = 2;

}  // namespace pb::app
