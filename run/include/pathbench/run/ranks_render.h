#pragma once
// One frame over every MPI rank of the run (issue 13), and the single-process render
// where there is one rank. Each rank traces samples of every pixel on its own device
// (GPU ranks: local rank % visible GPUs; CPU ranks: their share of the node's cores),
// statically split (share_of) or in chunks from rank 0's counter (SampleDispenser);
// the integer film sums are reduced exactly onto rank 0, which alone gets the film and
// the report (with extra["ranks"]: per-rank devices, times, rays, memory, load balance
// and parallel efficiency). Any rank's failure ends the frame on every rank at the next
// agreement with that rank's message (on_every_rank).
#include <functional>
#include <string>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/run/run.h"

namespace pb::run {

// Renders on every rank; true on the rank that holds the result (rank 0, or the only
// process), false elsewhere (its film and report are then its own share, not to be
// written). `run_key`: the caller's settings that must agree across ranks besides
// the RenderSettings and the scene (output paths, say); ranks whose keys or settings
// differ in anything but device and threads are refused.
bool render_ranks(const Scene& scene, const RenderSettings& settings, Film& film, RunReport& report,
                  const RunOptions& options = {}, const std::string& run_key = {});

// Runs `step` on this rank, then (with MPI) agrees with every other rank: when any failed,
// throws on every rank, on rank 0 the failure (InputError for bad input, otherwise
// std::runtime_error) with the failing rank named, elsewhere PeerFailure (world.h). One
// process: `step`'s own exception, unchanged.
void on_every_rank(const std::function<void()>& step);

// `--device hybrid`: this rank's device name ("gpu" for the first local ranks, up to one
// per visible GPU and leaving at least one CPU rank per node; "cpu" for the rest).
// Other names are returned as they are. Throws InputError for hybrid in a single process.
std::string rank_device(const std::string& asked);

// The settings every rank must share, as "name=value" words: everything in `s` but the
// device, threads, progress and sample range, and the scene's content.
std::string settings_key(const Scene& scene, const RenderSettings& s);

}  // namespace pb::run
