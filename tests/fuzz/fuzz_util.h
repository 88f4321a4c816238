#pragma once
// Shared by the fuzz targets: what counts as a finding. Bad input must come back as
// pb::InputError; anything else that escapes (another exception, a crash, a sanitizer
// report, a leak) is a bug, and libFuzzer stops with the input that caused it.
#include <fmt/core.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_warnings.h"
#include "readers/readers.h"

namespace pb::fuzz {

inline std::string text_of(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

// Runs f; swallows InputError only (and checks it carries a message). The readers'
// warnings and notes are collected, not printed: a target that warns on most inputs
// (OFF's COFF colours, its default light) otherwise writes gigabytes of log an hour.
template <class F> void expect_clean(F&& f) {
  SceneWarningCollector quiet;
  try {
    f();
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) __builtin_trap();
  }
}

// A FileReader over texts held in memory, so a target explores its format rather than
// the file system: text_for(path) is the file's contents, one over max_bytes is an
// InputError as on disk, and a name containing "missing" does not exist.
template <class TextFor> scene_io::FileReader memory_reader(TextFor text_for) {
  return {[text_for](const std::string& path, const char* what, uint64_t max_bytes) {
            std::string text = text_for(path);
            if (text.size() > max_bytes) throw InputError(fmt::format("{}: {} over the limit", path, what));
            return text;
          },
          [](const std::string& path) { return path.find("missing") == std::string::npos; }};
}

}  // namespace pb::fuzz
