#pragma once
// The film of a render, made ready in one place for one process (run.cpp) and for every
// MPI rank (ranks_render.cpp).
#include <functional>

#include "pathbench/common/film.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/run.h"

namespace pb::run {

// (Re)sizes `film` to the settings, keeping its buffers where size and variance already
// match (a film that keeps variance sums keeps them: the accuracy study asks for them so),
// and begins it for the whole frame's spp: the fixed-point scale every strategy, device
// and rank shares.
void prepare_film(const Scene& scene, const RenderSettings& s, const RunOptions& options, Film& film);

// render()'s checks before any build: the settings, the device present, what its tracer runs.
void check_for_tracer(const RenderSettings& s);
// Everything render() does around the tracer call `trace` (which fills the tracer's fields
// of `report`): checks, film, report fields, load, energy, fingerprint, film hash. render()
// and BuiltScene::render (built_scene.h) differ only in `trace`.
void render_with(const Scene& scene, const RenderSettings& s, Film& film, RunReport& report, const RunOptions& options,
                 const std::function<void()>& trace);

}  // namespace pb::run
