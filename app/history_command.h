#pragma once
// `pathbench history ...`: handed over to the Python history tool (tools/history) the way git
// runs its subcommands: the process is replaced by `python -m history ARGS...`, so arguments,
// output and the exit status pass through untouched.

namespace pb::app {

// argv: the arguments after `history`. Returns only when the hand-over failed (exit status 2).
// `module`: the tools/ package run (`pathbench suite` hands over to tools/suite the same way).
int run_history(int argc, char** argv, const char* module = "history");

}  // namespace pb::app
