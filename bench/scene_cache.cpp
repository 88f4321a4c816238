#include "scene_cache.h"

#include <map>

#include "pathbench/scene_io/scene_library.h"

namespace pb::bench {

namespace {
struct Cache {
  std::string name;
  std::shared_ptr<const Scene> scene;
  std::map<std::string, std::shared_ptr<void>> extras;
};
Cache& cache() {
  static Cache c;
  return c;
}
void switch_to(const std::string& name) {
  Cache& c = cache();
  if (c.name == name) return;
  c.extras.clear();  // Embree scenes and rays of the previous scene first
  c.scene.reset();
  c.name = name;
}
}  // namespace

std::shared_ptr<const Scene> cached_scene(const std::string& name) {
  switch_to(name);
  Cache& c = cache();
  if (!c.scene) c.scene = std::make_shared<const Scene>(load_scene(name));
  return c.scene;
}

std::shared_ptr<void> cached_extra(const std::string& scene, const std::string& kind) {
  switch_to(scene);
  auto it = cache().extras.find(kind);
  return it == cache().extras.end() ? nullptr : it->second;
}

void store_extra(const std::string& scene, const std::string& kind, std::shared_ptr<void> value) {
  switch_to(scene);
  cache().extras[kind] = std::move(value);
}

}  // namespace pb::bench
