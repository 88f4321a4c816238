#pragma once
// The film of a render, made ready in one place for one process (run.cpp) and for every
// MPI rank (ranks_render.cpp).
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

}  // namespace pb::run
