#include "pathbench/common/scene_warnings.h"

#include <fmt/core.h>

#include "pathbench/common/display_text.h"

namespace pb {

namespace {
thread_local SceneWarningCollector* t_collector = nullptr;
}

void scene_message(SceneMessage kind, const std::string& text) {
  if (t_collector) {
    t_collector->messages_.push_back({kind, text});
    return;
  }
  fmt::print(stderr, "{}: {}\n", kind == SceneMessage::Warning ? "warning" : "note", terminal_safe(text));
}

SceneWarningCollector::SceneWarningCollector() : outer_(t_collector) { t_collector = this; }
SceneWarningCollector::~SceneWarningCollector() { t_collector = outer_; }

}  // namespace pb
