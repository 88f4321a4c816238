#pragma once
// JSON parsing for untrusted files (scene files, benchmark JSON, glTF before tinygltf):
// nesting depth and keys per object are bounded, so a file within its size limit cannot
// ask for gigabytes (64 MiB of '[' is 67 million nested arrays), overflow a recursive
// parser's stack, or cost quadratic time (an ordered_json object finds each new key by
// a linear search).
//
// The bounds are checked by one pass over the text before nlohmann parses it, not by a
// parser callback: nlohmann 3.11's callback parser searches the enclosing array for
// discarded values at the end of every object, so an array of a million objects took
// minutes (issue 34: 10^6 JSON instances, 133 s).
#include <fmt/core.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "pathbench/common/errors.h"

namespace pb {

inline constexpr int kMaxJsonDepth = 64;
inline constexpr size_t kMaxJsonObjectKeys = 10000;

struct JsonBounds {
  int max_depth = kMaxJsonDepth;
  size_t max_keys = kMaxJsonObjectKeys;  // members of one object
  uint64_t max_values = UINT64_MAX;       // in all (a value per comma and per container, and the root)
};

// Throws InputError naming `path` and the limit where `text` goes past `bounds`. Only
// brackets, colons and commas outside strings are counted (no recursion), so malformed
// JSON is left to the parser to word.
inline void check_json_bounds(std::string_view text, const std::string& path, const JsonBounds& bounds = {}) {
  std::vector<size_t> keys;  // per open container: keys so far (SIZE_MAX for an array)
  uint64_t values = 1;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    switch (c) {
      case '"': in_string = true; break;
      case '{':
      case '[':
        if (keys.size() >= size_t(bounds.max_depth))
          throw InputError(fmt::format("{}: JSON nested deeper than {} levels (the supported maximum)", path,
                                       bounds.max_depth));
        keys.push_back(c == '{' ? 0 : SIZE_MAX);
        [[fallthrough]];
      case ',':
        if (++values > bounds.max_values)
          throw InputError(fmt::format("{}: more than {} JSON values (the supported maximum)", path, bounds.max_values));
        break;
      case ':':
        if (!keys.empty() && keys.back() != SIZE_MAX && ++keys.back() > bounds.max_keys)
          throw InputError(fmt::format("{}: a JSON object with more than {} keys", path, bounds.max_keys));
        break;
      case '}':
      case ']':
        if (!keys.empty()) keys.pop_back();
        break;
      default: break;
    }
  }
}

// Parses `text` within the default bounds; nlohmann's own parse errors propagate
// (callers word them), the bounds throw InputError naming `path`.
template <class Json> Json parse_json_bounded(const std::string& text, const std::string& path) {
  check_json_bounds(text, path);
  return Json::parse(text);
}

}  // namespace pb
