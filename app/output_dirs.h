#pragma once
// Where the subcommands write when the user names no folder: pathbench-out/ in the current
// directory (git-ignored in the source tree), never the committed results/. The committed
// results/<machine>/ are written only when a maintainer asks (--update-committed).
#include <string>

namespace pb::app {

inline constexpr const char* kDefaultOutRoot = "pathbench-out";

// `explicit_dir` if given; else results/<machine>/<sub> with --update-committed; else
// pathbench-out/<machine>/<sub>.
inline std::string output_dir(const std::string& explicit_dir, bool update_committed, const std::string& machine,
                              const std::string& sub = "") {
  if (!explicit_dir.empty()) return explicit_dir;
  std::string dir = std::string(update_committed ? "results" : kDefaultOutRoot) + "/" + machine;
  if (!sub.empty()) dir += "/" + sub;
  return dir;
}

}  // namespace pb::app
