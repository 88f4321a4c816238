#pragma once
// JSON parsing for untrusted files (scene files, benchmark JSON): nesting depth and
// keys per object are bounded, so a file within its size limit cannot ask for
// gigabytes (64 MiB of '[' is 67 million nested arrays) or quadratic time (an
// ordered_json object finds each new key by a linear search).
#include <fmt/core.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pathbench/common/errors.h"

namespace pb {

inline constexpr int kMaxJsonDepth = 64;
inline constexpr size_t kMaxJsonObjectKeys = 10000;

// Parses `text`; nlohmann's own parse errors propagate (callers word them), the two
// limits throw InputError naming `path`.
template <class Json> Json parse_json_bounded(const std::string& text, const std::string& path) {
  std::vector<size_t> keys;  // per open object: keys so far
  auto guard = [&](int depth, typename Json::parse_event_t event, Json&) {
    using E = typename Json::parse_event_t;
    if (depth > kMaxJsonDepth)
      throw InputError(fmt::format("{}: JSON nested deeper than {} levels", path, kMaxJsonDepth));
    if (event == E::object_start) keys.push_back(0);
    if (event == E::object_end && !keys.empty()) keys.pop_back();
    if (event == E::key && !keys.empty() && ++keys.back() > kMaxJsonObjectKeys)
      throw InputError(fmt::format("{}: a JSON object with more than {} keys", path, kMaxJsonObjectKeys));
    return true;
  };
  return Json::parse(text, guard);
}

}  // namespace pb
