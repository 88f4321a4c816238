#pragma once
// The environment every benchmark JSON carries (benchmark::AddCustomContext): CPU
// model and threads, GPU name / driver / CUDA where present, compiler and flags, git
// revision, date, preset.
#include <string>

namespace pb::bench {

void add_environment_context(const std::string& preset);

}  // namespace pb::bench
