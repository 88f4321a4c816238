#pragma once
// The Embree + TBB CPU tracer.
#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::cpu {

// Renders `scene` with settings.strategy (pixel or wavefront) into `film`, which
// must have the settings' size; fills `report`. Throws InputError on settings the
// CPU tracer cannot run (e.g. the paper-queue strategy).
void render(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report);

// Default number of paths in flight for the wavefront strategy.
uint64_t default_paths_in_flight(int threads);

}  // namespace pb::cpu
