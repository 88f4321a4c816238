#include "pathbench/bvh/host_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>

#include "pathbench/bvh/path_trace.h"
#include "pathbench/common/features.h"

namespace pb::bvh {

HostGpuTracer::HostGpuTracer(const Scene& scene, Instancing instancing)
    : scene_(scene), bvh_(build_scene_bvh(scene, GpuBvhOptions::from_env(instancing))) {}

void HostGpuTracer::render(const RenderSettings& settings, Film& film, RunReport& report) const {
  const SceneView view = scene_.view();
  const BvhView bvh = bvh_.view();
  const PathConfig c = settings.path_config();
  const uint32_t spp = c.spp;
  // The band of rows traced (a rank's chunk, or the frame), split by pixels: a chunk of a
  // few rows must still keep every thread busy.
  const uint32_t p0 = c.first_pixel, p1 = p0 + settings.traced_pixels();
  std::atomic<uint64_t> bounce{0}, shadow{0}, discarded{0};
  // The GPU's choice of kernel (pixel.cu's run_pixel): double precision and the
  // Moeller-Trumbore test switch on the layout at run time, as there; the same code.
  auto trace_pixels = [&](auto kinds, auto real, auto watertight) {
    constexpr uint32_t K = decltype(kinds)::value;
    using T = typename decltype(real)::type;
    constexpr bool W = decltype(watertight)::value;
    tbb::parallel_for(tbb::blocked_range<uint32_t>(p0, p1, 16), [&](const tbb::blocked_range<uint32_t>& pixels) {
      uint32_t n_bounce = 0, n_shadow = 0, n_discarded = 0;
      for (uint32_t pixel = pixels.begin(); pixel < pixels.end(); ++pixel)
        for (uint32_t k = 0; k < spp; ++k) {
          const Vec3f L = trace_path_bvh<K, T, W, kAnyKind>(view, bvh, c, pixel, c.first_sample + k, n_bounce, n_shadow);
          if (!film.add(pixel, L)) ++n_discarded;  // one writer per pixel: pixels are split
        }
      bounce += n_bounce;
      shadow += n_shadow;
      discarded += n_discarded;
    });
  };
  const auto t0 = std::chrono::steady_clock::now();
  tbb::task_arena arena(settings.threads > 0 ? settings.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    with_features(view.material_kinds, [&](auto kinds) {
      if (settings.precision == Precision::Double) trace_pixels(kinds, std::type_identity<double>{}, std::true_type{});
      else if (!settings.watertight) trace_pixels(kinds, std::type_identity<float>{}, std::false_type{});
      else trace_pixels(kinds, std::type_identity<float>{}, std::true_type{});
    });
  });
  const uint64_t paths = settings.traced_samples();
  report.rays.camera += paths;
  report.rays.bounce += bounce;
  report.rays.shadow += shadow;
  report.paths += paths;
  report.discarded_samples += discarded;
  report.extra["instancing"] = instancing_report(scene_, bvh_, settings.instancing);
  report.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace pb::bvh
