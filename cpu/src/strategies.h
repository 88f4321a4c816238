#pragma once
// The CPU strategies. Both run the shared path step; they differ only in how rays
// are grouped for Embree and how work is spread over threads.
#include <atomic>
#include <cstdint>

#include "pathbench/cpu/embree_scene.h"
#include "pathbench/common/features.h"
#include "pathbench/common/film.h"
#include "pathbench/common/progress.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::cpu {

// On the functions that run the path step per path: inline the whole step into them
// (g++ otherwise keeps path_hit out of line: a call, spills and reloads per vertex).
#define PB_CPU_FLATTEN [[gnu::flatten]]

struct TraceJob {
  const EmbreeScene& embree;
  SceneView scene;
  PathConfig config;
  uint32_t rows;  // rows traced: config.first_pixel / width onwards
  Film& film;
  Progress& progress;
  Isa isa;  // resolved (cpu/isa.h): the batched path step's instruction set, or Scalar
};

struct TraceTotals {
  RayCounts rays;
  uint64_t paths = 0;
  uint64_t discarded = 0;
  uint64_t state_bytes_per_path = 0;
  uint64_t paths_in_flight = 0;
  uint64_t pool_bytes = 0;
  uint64_t table_bytes = 0;  // wavefront: the batched shading's per-triangle table (shade_batch.h)
  Isa isa = Isa::Scalar;     // the path step's ISA: a vector one where the batched step ran
};

// Rays are counted where they are traced. A path's first ray is its camera ray whatever
// answers it (a closest-hit query, or at 0 bounces the last-vertex occlusion test);
// later rays count as `otherwise` (bounce or shadow).
inline void count_ray(RayCounts& rays, uint32_t depth, uint64_t RayCounts::*otherwise) {
  ++(depth == 0 ? rays.camera : rays.*otherwise);
}

// Both strategies run the path step in the scalar type T (float or double, the
// --precision setting; instantiated for both in their .cpp files). Embree finds the hit
// triangle in float either way; surface_hit recomputes the hit in T.
// Each is compiled per set of material kinds `Kinds` (render_*.cpp and
// render_*_all_kinds.cpp), and the entry points pick one per render from the scene's
// features (features.h).
// One thread per image tile; each pixel sample traced as its own path with single rays
// (rtcIntersect1/rtcOccluded1), the path steps of up to 16 (AVX-512) or 8 (AVX2) samples
// of a pixel run side by side where the batched shading applies (render_pixel.cpp).
template <class T, uint32_t Kinds> TraceTotals render_pixel_parallel_for(const TraceJob& job);
template <class T> TraceTotals render_pixel_parallel(const TraceJob& job) {
  return with_features(job.scene.material_kinds,
                       [&](auto kinds) { return render_pixel_parallel_for<T, decltype(kinds)::value>(job); });
}
// Bounded pool of paths per thread; each stage runs over the whole pool, rays go to
// Embree in packets of 16 (AVX-512) or 8; finished paths are replaced by new samples.
template <class T, uint32_t Kinds> TraceTotals render_wavefront_for(const TraceJob& job, uint64_t paths_in_flight);
template <class T> TraceTotals render_wavefront(const TraceJob& job, uint64_t paths_in_flight) {
  return with_features(job.scene.material_kinds,
                       [&](auto kinds) { return render_wavefront_for<T, decltype(kinds)::value>(job, paths_in_flight); });
}

}  // namespace pb::cpu
