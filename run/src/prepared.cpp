#include "pathbench/run/prepared.h"

#include <chrono>
#include <stdexcept>

#include "pathbench/cpu/render.h"
#include "film_setup.h"
#if PATHBENCH_HAVE_CUDA
#include "pathbench/gpu/render.h"
#endif

namespace pb::run {

struct PreparedScene::Built {
  std::unique_ptr<cpu::EmbreeScene> embree;
#if PATHBENCH_HAVE_CUDA
  std::unique_ptr<gpu::GpuScene> gpu;
#endif
};

PreparedScene::PreparedScene(const Scene& scene, const RenderSettings& settings)
    : scene_(scene), built_for_(settings), built_(std::make_unique<Built>()) {
  check_for_tracer(settings);
  const auto t0 = std::chrono::steady_clock::now();
  if (settings.device == Device::Cpu) {
    built_->embree = cpu::make_embree_scene(scene, settings.watertight, settings.embree_layout, settings.instancing);
  } else {
#if PATHBENCH_HAVE_CUDA
    built_->gpu = std::make_unique<gpu::GpuScene>(scene, settings.instancing);
#endif
  }
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

PreparedScene::~PreparedScene() = default;

bool PreparedScene::serves(const RenderSettings& s) const {
  const RenderSettings& b = built_for_;
  return s.device == b.device && s.instancing == b.instancing && s.watertight == b.watertight &&
         s.embree_layout == b.embree_layout;
}

void PreparedScene::render(const RenderSettings& s, Film& film, RunReport& report, const RunOptions& options) const {
  if (!serves(s)) throw std::logic_error("PreparedScene::render: settings that need another build");
  render_with(scene_, s, film, report, options, [&] {
    if (s.device == Device::Cpu) {
      cpu::render(scene_, *built_->embree, s, film, report);
    } else {
#if PATHBENCH_HAVE_CUDA
      gpu::render(scene_, *built_->gpu, s, film, report, options.profile);
#endif
    }
  });
}

}  // namespace pb::run
