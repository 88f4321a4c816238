#pragma once
// `pathbench history ...`: handed over to the Python history tool (tools/history) the way git
// runs its subcommands: the process is replaced by `python -m history ARGS...`, so arguments,
// output and the exit status pass through untouched.

namespace pb::app {

// argv: the arguments after `history`. Returns only when the hand-over failed (exit status 2).
int run_history(int argc, char** argv);

}  // namespace pb::app
