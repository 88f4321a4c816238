#pragma once
// What the run layer will hand each MPI rank (issue 13), kept apart from MPI itself so
// that it is tested in every build: a rank's share of each pixel's samples, and the
// exact reduction of the rank films' integer sums.
#include <cstdint>

#include "pathbench/common/film.h"

namespace pb::run {

// Samples [first, first + count) of every pixel. The random stream is keyed by pixel
// and sample, never by rank, so any split of the samples gives the same image.
struct SampleShare {
  uint32_t first = 0, count = 0;
};
// Rank `rank` of `ranks`: a contiguous share of `spp`, the first spp % ranks ranks one
// sample more. Throws std::invalid_argument for rank >= ranks or ranks == 0.
SampleShare share_of(uint32_t rank, uint32_t ranks, uint32_t spp);

// Adds `part`'s sums, counts and variance sums into `into` (same size, same scale: both
// begun for the whole frame). Integer sums: exact and order-free. Throws
// std::invalid_argument when the films do not match, std::overflow_error when a sum
// would leave Film's range (|sum| < 2^62 + 2^62).
void reduce_film(Film& into, const Film& part);

}  // namespace pb::run
