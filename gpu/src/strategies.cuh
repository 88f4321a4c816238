#pragma once
// What the orchestration (render.cu) asks of each GPU strategy: a frame's result, which
// shadow records the settings need, and the pixel strategy's entry (pixel.cu). The
// wavefront and paper-queue strategies are PathPool (path_pool.cuh).
#include <cuda_runtime.h>

#include <cstdint>

#include "cuda_util.h"
#include "device_film.cuh"
#include "gpu_scene_impl.cuh"
#include "pathbench/common/path.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::gpu {

struct FrameResult {
  Stats stats{};
  uint64_t state_bytes_per_path = 0, paths_in_flight = 0, pool_bytes = 0;
  uint64_t iterations = 0;
};

// Which shadow records a frame needs: light-sampling rays, the last vertex's emitter
// queries (bounded paths, few emitters: path_at_final_vertex), and pairs of both.
struct ShadowUse {
  bool records = false;
  bool pairs = false;
  static ShadowUse of(const Scene& scene, const RenderSettings& settings) {
    const bool lights = !scene.emitters.empty();
    const bool nee = lights && settings.sampling == Sampling::Nee;
    const bool final_queries = lights && settings.max_bounces > 0 && scene.emitters.size() <= kMaxEmittersForFinalQuery;
    return {nee || final_queries, nee && final_queries};
  }
};

// The pixel megakernel over `total` samples (spp per pixel), compiled for the scene's
// material kinds; `stats` is its counter block on the device.
FrameResult run_pixel(Launcher& launch, cudaStream_t stream, const GpuScene::Impl& g, const PathConfig& c, uint32_t spp,
                      uint64_t total, FilmDev film, bool variance, Precision precision, bool watertight,
                      DeviceBuffer<Stats>& stats);

}  // namespace pb::gpu
