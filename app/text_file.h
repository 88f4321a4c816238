#pragma once
// Text output of the command line (reports, notes): written whole or not at all.
#include <string>

namespace pb::app {

// Writes text to `path` through a temporary file and a rename.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace pb::app
