#pragma once
// `pathbench suite ...`: the suite (issue 28) — every workload of scenes/suite/manifest.json
// on every device present, recorded into the history, one page. Handed over to the Python
// orchestrator (tools/suite) through the history command's launcher; it runs this binary's
// pathbench-bench (found through PATHBENCH_EXE, set here) for the measurements.

namespace pb::app {

// argv: the arguments after `suite`. Returns only when the hand-over failed (exit status 2).
int run_suite(int argc, char** argv);

}  // namespace pb::app
