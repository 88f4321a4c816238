#pragma once
// pathbench's per-user data folder: installed data that scene files may name without an
// absolute path (the suite's meshes, docs/suite-workloads.md). $PATHBENCH_DATA_DIR if set,
// else ${XDG_DATA_HOME:-$HOME/.local/share}/pathbench/data. Meshes live in <data>/meshes/.
#include <string>

namespace pb {

// The data folder (it need not exist).
std::string data_dir();

// "data:meshes/bunny00.off" -> <data>/meshes/bunny00.off; any other name unchanged.
bool is_data_path(const std::string& name);
std::string resolve_data_path(const std::string& name);

// The Debian package that provides a data file named by its path under the data folder
// ("meshes/bunny00.off" -> "libcgal-demo"), or "" when pathbench does not know one.
std::string data_file_package(const std::string& relative);

// One line for a missing data file: what is missing, where it was looked for, and what
// installs it (the package and scripts/install-deps.sh).
std::string missing_data_message(const std::string& name);

}  // namespace pb
