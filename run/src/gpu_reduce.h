#pragma once
// The GPU ranks' part of the film reduction (issue 30): where the build has NCCL
// (PATHBENCH_NCCL), GPU ranks on distinct GPUs add their device films on the GPUs
// (ncclReduce of the int64 sums, uint32 counts and double variance sums onto the lowest
// GPU rank, bootstrapped by MPI_Bcast of ncclGetUniqueId), and that rank alone downloads
// the sum; CPU ranks, and GPU ranks where NCCL cannot serve, go through MPI
// (World::reduce_film, reduce_film_rows) as before. Exact either way: the GPUs' sums are
// added unchecked only where the ranks' largest |sums| add up below 2^63, which no
// partial sum can then leave; otherwise every rank downloads and MPI's checked sum runs.
// nccl_film_reduce.cpp (with NCCL) and gpu_reduce_none.cpp (without) implement it.
#include <memory>
#include <string>
#include <vector>

#include "pathbench/common/film.h"

namespace pb::run {

class World;
class DeviceFilm;  // tracer.h: a GPU rank's film on its device

struct GpuReduction {
  bool nccl = false;   // the GPU ranks' films are reduced through NCCL (every rank knows)
  int root = -1;       // the world rank that ends with the GPU ranks' sum (the lowest GPU rank)
  std::string method;  // for the report: "nccl", "mpi"
  std::string why;     // why this method (NCCL missing, two ranks on one GPU, asked for, ...)
  std::string nccl_version;
};

// Collective over every rank, before the frame: `gpu` says whether this rank traces on a
// GPU (device `gpu_index`). NCCL is used where the build has it, two or more ranks are GPU
// ranks, no two of them share a GPU (NCCL refuses that), and PATHBENCH_FILM_REDUCE on
// rank 0 is not "mpi". Its communicator is made once per process and rank layout.
GpuReduction prepare_gpu_reduction(World& w, bool gpu, int gpu_index);

// Collective over the GPU ranks (r.nccl only), before the frame's clock starts: one
// reduction of the (cleared) device films and one overflow check, so that the frame's
// own reduction finds NCCL's connections made (NCCL makes them at a communicator's first
// collective: 0.16 s for 2 H100s, 0.34 s for 4) and the check's kernel loaded.
void warm_gpu_reduction(const GpuReduction& r, DeviceFilm* film);

// Collective over every rank, after the frame (r.nccl only): GPU ranks pass their device
// film, others null. True (on every rank) when the GPUs' films were added onto r.root's
// device film; false when the overflow bound refused (then nothing was added). `seconds`
// gets the time of the bound check and of NCCL's reduction on this rank.
bool reduce_gpu_films(World& w, const GpuReduction& r, DeviceFilm* film, double& bound_seconds,
                      double& nccl_seconds);

// While it lives, `film`'s host arrays are page-locked for the device's copies (the one
// download of a GPU rank's film runs at the bus's speed, not through a bounce buffer);
// nothing in a build without NCCL, or where locking fails. Made before the frame's clock
// starts, undone when the frame is over.
class PinnedFilm {
 public:
  PinnedFilm(Film& film, bool pin);
  ~PinnedFilm();
  PinnedFilm(const PinnedFilm&) = delete;
  PinnedFilm& operator=(const PinnedFilm&) = delete;

 private:
  std::vector<void*> pinned_;
};

}  // namespace pb::run
