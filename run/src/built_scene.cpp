#include "pathbench/run/built_scene.h"

#include <chrono>
#include <stdexcept>

#include "film_setup.h"

namespace pb::run {

BuiltScene::BuiltScene(const Scene& scene, const RenderSettings& settings) : scene_(scene), built_for_(settings) {
  check_for_tracer(settings);
  const auto t0 = std::chrono::steady_clock::now();
  prepared_ = tracer(settings.device).prepare(scene, settings);
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

BuiltScene::~BuiltScene() = default;

bool BuiltScene::serves(const RenderSettings& s) const {
  const RenderSettings& b = built_for_;
  return s.device == b.device && s.instancing == b.instancing && s.watertight == b.watertight &&
         s.embree_layout == b.embree_layout;
}

void BuiltScene::render(const RenderSettings& s, Film& film, RunReport& report, const RunOptions& options) const {
  if (!serves(s)) throw std::logic_error("BuiltScene::render: settings that need another build");
  render_with(scene_, s, film, report, options, [&] { prepared_->render(s, film, report, options.profile); });
}

}  // namespace pb::run
