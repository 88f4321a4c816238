#include "pathbench/scene_io/data_dir.h"

#include <fmt/core.h>

#include <cstdlib>
#include <filesystem>
#include <string_view>

namespace pb {

namespace {
constexpr std::string_view kPrefix = "data:";

const char* env(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? v : nullptr;
}

// Mesh files scripts/install-deps.sh installs, with the Debian package they come from.
constexpr std::pair<std::string_view, std::string_view> kKnown[] = {
    {"meshes/bunny00.off", "libcgal-demo"},
    {"meshes/armadillo.off", "libcgal-demo"},
    {"meshes/ChineseDragon-10kv.off", "libcgal-demo"},
    {"meshes/refined_elephant.off", "libcgal-demo"},
};
}  // namespace

std::string data_dir() {
  namespace fs = std::filesystem;
  if (const char* d = env("PATHBENCH_DATA_DIR")) return d;
  fs::path base;
  if (const char* x = env("XDG_DATA_HOME")) base = x;
  else if (const char* h = env("HOME")) base = fs::path(h) / ".local" / "share";
  else base = fs::path(".local") / "share";
  return (base / "pathbench" / "data").string();
}

bool is_data_path(const std::string& name) { return name.rfind(kPrefix, 0) == 0; }

std::string resolve_data_path(const std::string& name) {
  if (!is_data_path(name)) return name;
  return (std::filesystem::path(data_dir()) / name.substr(kPrefix.size())).string();
}

std::string data_file_package(const std::string& relative) {
  for (const auto& [file, package] : kKnown)
    if (relative == file) return std::string(package);
  return "";
}

std::string missing_data_message(const std::string& name) {
  const std::string relative = is_data_path(name) ? name.substr(kPrefix.size()) : name;
  const std::string package = data_file_package(relative);
  const std::string where = resolve_data_path(name);
  if (package.empty())
    return fmt::format("'{}': no such file (looked for {}; the data folder is $PATHBENCH_DATA_DIR, else "
                       "${{XDG_DATA_HOME:-$HOME/.local/share}}/pathbench/data)", name, where);
  return fmt::format("'{}': no such file (looked for {}): it comes from the Debian package {}; run "
                     "scripts/install-deps.sh (or set PATHBENCH_DATA_DIR to a data folder that has it)",
                     name, where, package);
}

}  // namespace pb
