#pragma once
// The Embree + TBB CPU tracer.
#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/cpu/embree_scene.h"

namespace pb::cpu {

// Traces `scene` with settings.strategy (pixel or wavefront) into `film`, and fills the
// CPU's fields of `report`. Called by the run layer (pathbench/run/run.h), which has
// validated the settings, sized and begun the film, and fills the common report fields
// (scene, settings, peak memory). Settings the CPU tracer cannot run (e.g. the
// paper-queue strategy) are refused before that, by validate_for_tracer (settings.h).
void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report);
// The same with the Embree scene built once by the caller (make_embree_scene with the
// settings' watertight and layout), for many renders of one scene: an MPI rank's chunks.
void render(const Scene& scene, const EmbreeScene& embree, const RenderSettings& settings, Film& film,
            RunReport& report);

// What report.extra["instancing"] says: asked, used, why, instances and prototypes
// (the scene's and those built), triangles traced flat, the acceleration structure's
// bytes (Embree's, after the build) and its build time.
nlohmann::json instancing_report(const Scene& scene, const EmbreeScene& embree, Instancing asked);

// Default number of paths in flight for the wavefront strategy.
uint64_t default_paths_in_flight(int threads);

}  // namespace pb::cpu
