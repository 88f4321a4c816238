#pragma once
// What the run layer will hand each MPI rank (issue 13), kept apart from MPI itself so
// that it is tested in every build: a rank's share of each pixel's samples, and the
// exact reduction of the rank films' integer sums.
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

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

// Whole batches: the CPU's pixel strategy traces a pixel's samples in packets of up to 16 (8
// with AVX2) from its block's first sample, and Embree's packet query answers a ray at an
// edge by its packet mates (issue 30: TinyIsa.AnswersDoNotDependOnPacketMates; the tiny test
// answers per ray, Embree's packets above its limit do not). CPU ranks therefore take samples
// in batches of kSampleBatch aligned to absolute sample indices (the last batch of a pixel
// short where spp is not a multiple), so each packet holds the samples one process's does,
// whatever the rank count or the chunks. (GPU ranks, and CPU ranks beside them, trace each
// ray alone: batch 1.)
constexpr uint32_t kSampleBatch = 16;
// share_of over whole batches of `batch` samples: [first, first + count) starts at a
// multiple of `batch` and ends at one or at spp; the first ranks get a batch more (the
// largest share is ceil(batches / ranks) batches), and the last ranks get nothing where there
// are fewer batches than ranks. batch 1: share_of.
SampleShare share_of(uint32_t rank, uint32_t ranks, uint32_t spp, uint32_t batch);
// The first unit at or after `u` (row-major rows x spp, UnitRange) where a batch of
// `batch` samples starts (sample % batch == 0); `units` (rows x spp) where none is left.
uint64_t batch_start_at_or_after(uint64_t u, uint32_t spp, uint32_t batch, uint64_t units);

// A block of the frame a tracer call traces: samples [first_sample, first_sample +
// samples) of every pixel of rows [first_row, first_row + rows).
struct FrameBlock {
  uint32_t first_row = 0, rows = 0, first_sample = 0, samples = 0;
  bool operator==(const FrameBlock&) const = default;
};

// Dynamic balancing hands out ranges of the frame's units, row-major: unit u is sample
// u % spp of every pixel of row u / spp. A range is thus mostly whole rows (all their
// samples), so a rank's part of the film is a band of rows and only those rows travel
// to rank 0 (World::reduce_film_rows); a GPU beside CPUs sends nothing it did not trace.
struct UnitRange {
  uint64_t first = 0, count = 0;
};
// The blocks of a range (at most three: a part row, whole rows, a part row), in order.
// Throws std::invalid_argument for a range outside rows x spp units.
std::vector<FrameBlock> blocks_of(UnitRange range, uint32_t spp, uint32_t rows);

// Rows [first, first + count): what a rank traced of the frame, merged and in order.
struct RowRange {
  uint32_t first = 0, count = 0;
  bool operator==(const RowRange&) const = default;
};
// Adds `block`'s rows to `rows` (sorted, merged where they touch or overlap).
void add_rows(std::vector<RowRange>& rows, const FrameBlock& block);

// into[i] += add[i] for i < n: integers checked (false where one overflowed, the rest
// still added), doubles (variance sums) summed. The one addition of rank films' values:
// add_rows_into, reduce_film and World::reduce_film_rows use it.
template <class T> bool add_values(T* into, const T* add, size_t n) {
  bool ok = true;
  for (size_t i = 0; i < n; ++i) {
    if constexpr (std::is_integral_v<T>) ok &= !__builtin_add_overflow(into[i], add[i], &into[i]);
    else into[i] += add[i];
  }
  return ok;
}

// Whether films whose largest |sums| are `largest` (one value per rank) add up without
// overflow in any order: their total is at most 2^63 - 1, which bounds every partial sum.
// The MPI (MPI_SUM) and NCCL (ncclSum) reductions add unchecked only where it holds.
bool sums_cannot_overflow(const std::vector<uint64_t>& largest);

// Adds `part`'s sums, counts and variance sums into `into` (same size, same scale: both
// begun for the whole frame). Integer sums: exact and order-free. Throws
// std::invalid_argument when the films do not match, std::overflow_error when a sum
// would leave Film's range (|sum| < 2^62 + 2^62).
void reduce_film(Film& into, const Film& part);
// The same for rows [first_row, first_row + rows) alone, `part` holding those rows' sums,
// counts and (where kept) variance sums in Film's order (pixel-major, 3 channels):
// `sums` 3 x width x rows values, `counts` width x rows, `sum_sq` 3 x width x rows or
// empty. Returns false (leaving the rest added) where a sum or count overflowed.
bool add_rows_into(Film& into, uint32_t first_row, uint32_t rows, const int64_t* sums, const uint32_t* counts,
                   const double* sum_sq);

}  // namespace pb::run
