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
#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
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
  int bands_asked = 0;  // rank 0's PATHBENCH_REDUCE_BANDS: 0 = auto (reduction_bands), else that many
};

// Overlap (issue 30, item 2): a static split's GPU ranks (every rank a GPU rank, NCCL)
// trace the frame in bands of rows, and each band's reduction (and the root's download of
// it) starts on NCCL's stream as soon as the band is traced, while the next band traces;
// only the last band's and the overflow bound are left after the ranks' tracing. Each band
// is one more tracer call (a launch and a synchronisation, and the megakernel's last wave),
// so small frames keep one band: `samples` (this rank's share, pixels x samples) of
// kBandSamples or more per band, at most kMaxBands bands and never more than the rows.
// `asked` > 0 (PATHBENCH_REDUCE_BANDS) fixes the count (still at most the rows).
inline constexpr uint64_t kBandSamples = uint64_t(1) << 26;  // ~15 ms of an H100 on the paper's box
inline constexpr uint32_t kMaxBands = 8;
inline uint32_t reduction_bands(uint64_t samples, uint32_t rows, int asked) {
  const uint64_t n = asked > 0 ? uint64_t(asked) : std::min<uint64_t>(kMaxBands, samples / kBandSamples);
  return uint32_t(std::max<uint64_t>(1, std::min<uint64_t>(n, rows)));
}
// Rows [first, first + count) of band `k` of `bands` over `rows` rows (as even as it goes).
inline std::pair<uint32_t, uint32_t> band_rows(uint32_t k, uint32_t bands, uint32_t rows) {
  const uint32_t a = uint32_t(uint64_t(rows) * k / bands), b = uint32_t(uint64_t(rows) * (k + 1) / bands);
  return {a, b - a};
}

// Collective over every rank, before the frame: `gpu` says whether this rank traces on a
// GPU (device `gpu_index`). NCCL is used where the build has it, two or more ranks are GPU
// ranks, no two of them share a GPU (NCCL refuses that), and PATHBENCH_FILM_REDUCE on
// rank 0 is not "mpi". Its communicator is made once per process and rank layout.
// PATHBENCH_REDUCE_BANDS on rank 0 (a count 1..64, or auto) sets bands_asked; another
// value: InputError.
GpuReduction prepare_gpu_reduction(World& w, bool gpu, int gpu_index);

// Collective over the GPU ranks (r.nccl only), before the frame's clock starts: one
// reduction of the (cleared) device films and one overflow check, so that the frame's
// own reduction finds NCCL's connections made (NCCL makes them at a communicator's first
// collective: 0.16 s for 2 H100s, 0.34 s for 4) and the check's kernel loaded.
// `band_root`: this rank is the root of a banded reduction (below): its receive buffer (a
// second film on its GPU: the banded reduction is out of place, so that the ranks' own
// films stay for MPI's checked sum where the bound refuses) is allocated here.
void warm_gpu_reduction(const GpuReduction& r, DeviceFilm* film, bool band_root = false);

// Banded (r.nccl, every rank a GPU rank): starts the reduction of rows [first_row,
// first_row + rows) of the GPU ranks' device films into the root's receive buffer and, on
// the root, its download into `host` (page-locked: PinnedFilm), on NCCL's stream; returns
// at once. Every GPU rank calls it for the same bands in the same order, after tracing
// them (a rank that traced nothing too).
void reduce_gpu_band(const GpuReduction& r, DeviceFilm* film, Film& host, bool root, uint32_t first_row,
                     uint32_t rows);
// After the last band: the overflow bound over every rank (collective), then waits for the
// bands' reductions. True: `host` on the root holds the GPU ranks' sums and counts; false:
// the bound refused, nothing of the banded sums may be used (every rank's device film is
// untouched: download them and add them through MPI's checked sum).
bool finish_gpu_bands(World& w, const GpuReduction& r, DeviceFilm* film, double& bound_seconds,
                      double& wait_seconds);

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
