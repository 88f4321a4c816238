#pragma once
// pathbench-bench over MPI ranks (issue 13): `mpirun -np N pathbench-bench ...`. Rank 0
// runs Google Benchmark as one process would; each iteration of a render benchmark is
// one frame over every rank (run::render_ranks: samples split, films reduced exactly,
// so the film hash is one process's). Google Benchmark picks iteration counts by
// timing on rank 0 alone, so the other ranks do not run it: they follow rank 0, which
// announces each frame by its benchmark's name (every rank registers the same
// benchmarks from the same command line), and "stop" at the end. Ray-cast benchmarks
// run on rank 0 alone while the others wait without spinning (World::announce).
#include <string>

#include "pathbench/common/film.h"
#include "pathbench/common/report.h"
#include "pathbench/common/scene.h"
#include "render_bench.h"

namespace pb::bench {

// Ranks of this run (1 without mpirun or without MPI).
int bench_ranks();
// Whether this process is a rank other than 0: it follows instead of benchmarking.
bool bench_follower();

// Every render case, registered under its benchmark name, so a follower finds the
// frame rank 0 announces.
void remember_render_case(const std::string& name, const RenderCase& c);

// Rank 0, one render benchmark iteration over the ranks: announces `name`, then renders
// the frame (run::render_ranks). Throws as render_ranks does (a failing rank named).
void render_frame_over_ranks(const std::string& name, const Scene& scene, const RenderSettings& s, Film& film,
                             RunReport& report);

// A follower: renders its share of every frame rank 0 announces until rank 0 says stop;
// returns the exit status (0, or 1 when this rank failed outside an agreed frame).
int follow_rank0();
// Rank 0: tells the followers the run is over (once; later calls do nothing).
void release_followers();

}  // namespace pb::bench
