#pragma once
// The converged reference of `pathbench accuracy`: the best estimator the tracer has
// (unbounded paths ended by Russian roulette, light sampling + MIS, watertight,
// double precision where the device runs it) at many samples per pixel, with its
// variance image. Rendered once and cached as PFM + JSON, keyed by scene, size,
// device, spp and kReferenceVersion.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::app {

// Bump when the estimator (common/path.h), the built-in scenes or the reference's
// settings change, so that cached references are rendered again.
inline constexpr int kReferenceVersion = 1;

struct Reference {
  std::vector<float> mean, var;  // RGB; var: variance of the per-pixel mean
  nlohmann::json info;           // settings, seconds, file names, whether it came from the cache
};

// Renders like run::render, except that a GPU refusing the settings
// (InputError, e.g. a tracer without double precision) returns false with the reason
// instead of throwing: the sweep notes it and goes on. CPU errors still throw.
// `all_ranks`: over every MPI rank (run::render_ranks; rank 0 gets the film), as the
// reference is rendered; the sweep renders on rank 0 alone.
bool render_unless_gpu_refuses(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report,
                               std::string& refusal, bool all_ranks = false);

// The reference's settings: `base` supplies size, device, strategy and threads.
RenderSettings reference_settings(const RenderSettings& base, uint32_t spp);

// Loads the cached reference from `dir`, or renders it there (also when
// `regenerate`). `progress` shows the render's progress bar. Under mpirun every rank
// renders a share of the reference (rank 0's cache decides whether to); only rank 0
// gets it and writes it, the others return an empty Reference and leave the sweep to it.
Reference load_or_render_reference(const Scene& scene, const RenderSettings& base, uint32_t spp,
                                   const std::string& dir, bool regenerate, bool progress);

}  // namespace pb::app
