#pragma once
// One scene (and whatever a benchmark family derives from it: an Embree scene, stored
// rays) kept between benchmarks of that scene. Asking for another scene drops all of
// it first, so at most one large scene is resident at a time. Presets list benchmarks
// grouped by scene.
#include <memory>
#include <string>

#include "pathbench/common/scene.h"

namespace pb::bench {

// The scene by built-in name or path (pb::load_scene); throws what load_scene throws.
std::shared_ptr<const Scene> cached_scene(const std::string& name);

// A derived object for the current scene, keyed by `kind`; null if none yet.
std::shared_ptr<void> cached_extra(const std::string& scene, const std::string& kind);
void store_extra(const std::string& scene, const std::string& kind, std::shared_ptr<void> value);

}  // namespace pb::bench
