#include "compare_command.h"

namespace pb::app {

void add_compare_options(CLI::App& cmd, CompareOptions& o) {
  cmd.add_option("base", o.base, "baseline Google Benchmark JSON (--benchmark_repetitions=9 or more)")->required();
  cmd.add_option("new", o.next, "new Google Benchmark JSON to judge against the baseline")->required();
  cmd.add_option("--threshold", o.threshold, "minimum relative slowdown of the median time that counts")
      ->capture_default_str();
  cmd.add_option("--alpha", o.alpha, "significance level of the two-sided Mann-Whitney U test")->capture_default_str();
  cmd.add_option("--min-repetitions", o.min_repetitions, "repetitions each benchmark needs")->capture_default_str();
  cmd.add_flag("--quiet", o.quiet, "print only the verdict (text format)");
  cmd.add_flag("--strict", o.strict,
               "refuse (exit 2) when the runs differ in machine fingerprint, build, settings, Embree layout or load");
  cmd.add_option("--format", o.format, "text, json or markdown")->capture_default_str();
  cmd.footer("Exit status: 0 no regression, 1 some benchmark regressed, 2 bad input (a missing or malformed "
             "file, a field of the wrong type, no benchmark in common, or --strict and the runs differ; one "
             "message naming the file and field), 3 an internal failure. Names from the files are shown with "
             "control characters escaped.");
}

}  // namespace pb::app
