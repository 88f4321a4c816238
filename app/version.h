#pragma once
// `pathbench --version`: the version, the git revision it was built from, and one line
// of build flags (what a result must be reproduced with).
#include <string>

namespace pb::app {

std::string version_text();
const char* version_number();  // "0.1.0" (CMake's project version)

}  // namespace pb::app
