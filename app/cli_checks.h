#pragma once
// Option checks shared by the subcommands.
#include <CLI/CLI.hpp>

#include <string>

namespace pb::app {

// CLI11 reads "-1" into an unsigned option as 2^64 - 1 (strtoull wraps it); refuse the
// sign before it converts. Attach to every unsigned option: ->check(non_negative()).
inline CLI::Validator non_negative() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        const auto first = value.find_first_not_of(" \t");
        if (first != std::string::npos && value[first] == '-') return "must be >= 0 (got " + value + ")";
        return {};
      },
      "", "non-negative");
}

}  // namespace pb::app
