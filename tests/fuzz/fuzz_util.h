#pragma once
// Shared by the fuzz targets: what counts as a finding. Bad input must come back as
// pb::InputError; anything else that escapes (another exception, a crash, a sanitizer
// report, a leak) is a bug, and libFuzzer stops with the input that caused it.
#include <cstddef>
#include <cstdint>
#include <string>

#include "pathbench/common/errors.h"

namespace pb::fuzz {

inline std::string text_of(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

// Runs f; swallows InputError only (and checks it carries a message).
template <class F> void expect_clean(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) __builtin_trap();
  }
}

}  // namespace pb::fuzz
