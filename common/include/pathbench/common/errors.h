#pragma once
// Bad input (scene files, settings) is reported as one InputError: the CLI prints its
// message and exits with status 2, before any output file is opened.
#include <stdexcept>
#include <string>

namespace pb {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The exit-status contract (docs/reference.md, "Exit codes"): 0 done, 1 a regression found
// (compare, history), 2 a user error, anything else a bug -- kExitFailed for an
// unexpected exception, so that a script never reads a crash as "regression".
constexpr int kExitRegression = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitFailed = 3;

}  // namespace pb
