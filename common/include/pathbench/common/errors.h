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

constexpr int kExitBadInput = 2;

}  // namespace pb
