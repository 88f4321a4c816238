#include "pathbench/run/ranks.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "pathbench/run/world.h"

namespace pb::run {

int launcher_rank() {
  for (const char* v : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})  // OpenMPI, PMIx (srun), PMI (hydra)
    if (const char* r = std::getenv(v)) return std::max(0, std::atoi(r));
  return -1;
}

SampleShare share_of(uint32_t rank, uint32_t ranks, uint32_t spp) {
  if (ranks == 0 || rank >= ranks) throw std::invalid_argument("share_of: rank out of range");
  const uint32_t base = spp / ranks, extra = spp % ranks;
  const uint32_t first = rank * base + (rank < extra ? rank : extra);
  return {first, base + (rank < extra ? 1u : 0u)};
}

SampleShare share_of(uint32_t rank, uint32_t ranks, uint32_t spp, uint32_t batch) {
  if (batch <= 1) return share_of(rank, ranks, spp);
  // The first ranks take the extra batches, as share_of's extra samples: rank 0, whose report
  // describes the tracer, traces whenever there is a batch.
  const uint32_t batches = spp / batch + (spp % batch ? 1 : 0);
  const SampleShare b = share_of(rank, ranks, batches);
  const uint32_t first = uint32_t(std::min<uint64_t>(uint64_t(b.first) * batch, spp));
  const uint32_t end = uint32_t(std::min<uint64_t>(uint64_t(b.first + b.count) * batch, spp));
  return {first, end - first};
}

uint64_t batch_start_at_or_after(uint64_t u, uint32_t spp, uint32_t batch, uint64_t units) {
  if (batch <= 1 || u >= units) return std::min(u, units);
  const uint64_t row = u / spp, sample = u % spp;
  const uint64_t up = (sample + batch - 1) / batch * batch;  // the next batch's first sample
  return std::min(up < spp ? row * spp + up : (row + 1) * spp, units);
}

std::vector<FrameBlock> blocks_of(UnitRange range, uint32_t spp, uint32_t rows) {
  if (spp == 0 || range.first > uint64_t(rows) * spp || range.count > uint64_t(rows) * spp - range.first)
    throw std::invalid_argument("blocks_of: the range leaves the frame");
  std::vector<FrameBlock> blocks;
  uint64_t u = range.first;
  const uint64_t end = range.first + range.count;
  while (u < end) {
    const uint32_t row = uint32_t(u / spp), sample = uint32_t(u % spp);
    if (sample != 0 || end - u < spp) {  // part of one row: to its end or to the range's
      const uint32_t n = uint32_t(std::min<uint64_t>(spp - sample, end - u));
      blocks.push_back({row, 1, sample, n});
      u += n;
    } else {  // whole rows
      const uint32_t n = uint32_t((end - u) / spp);
      blocks.push_back({row, n, 0, spp});
      u += uint64_t(n) * spp;
    }
  }
  return blocks;
}

void add_rows(std::vector<RowRange>& rows, const FrameBlock& block) {
  if (block.rows == 0 || block.samples == 0) return;
  RowRange r{block.first_row, block.rows};
  auto it = std::lower_bound(rows.begin(), rows.end(), r, [](const RowRange& a, const RowRange& b) { return a.first < b.first; });
  it = rows.insert(it, r);
  // Merge with the neighbours it touches or overlaps.
  if (it != rows.begin()) {
    auto prev = it - 1;
    if (uint64_t(prev->first) + prev->count >= it->first) {
      const uint64_t e = std::max(uint64_t(prev->first) + prev->count, uint64_t(it->first) + it->count);
      prev->count = uint32_t(e - prev->first);
      it = rows.erase(it) - 1;
    }
  }
  while (it + 1 != rows.end() && uint64_t(it->first) + it->count >= (it + 1)->first) {
    const uint64_t e = std::max(uint64_t(it->first) + it->count, uint64_t((it + 1)->first) + (it + 1)->count);
    it->count = uint32_t(e - it->first);
    rows.erase(it + 1);
  }
}

bool add_rows_into(Film& into, uint32_t first_row, uint32_t rows, const int64_t* sums, const uint32_t* counts,
                   const double* sum_sq) {
  if (uint64_t(first_row) + rows > into.height()) throw std::invalid_argument("add_rows_into: rows outside the film");
  const size_t px0 = size_t(first_row) * into.width(), px = size_t(rows) * into.width();
  bool ok = add_values(into.raw_sums().data() + px0 * 3, sums, px * 3);
  ok &= add_values(into.counts().data() + px0, counts, px);
  if (into.has_variance() && sum_sq) add_values(into.raw_sum_sq().data() + px0 * 3, sum_sq, px * 3);
  return ok;
}

bool sums_cannot_overflow(const std::vector<uint64_t>& largest) {
  unsigned __int128 bound = 0;
  for (uint64_t v : largest) bound += v;
  return bound <= (unsigned __int128)INT64_MAX;
}

void reduce_film(Film& into, const Film& part) {
  if (into.width() != part.width() || into.height() != part.height() || into.scale() != part.scale() ||
      into.has_variance() != part.has_variance())
    throw std::invalid_argument("reduce_film: the films differ in size, scale or variance");
  if (!add_rows_into(into, 0, into.height(), part.raw_sums().data(), part.counts().data(),
                     part.has_variance() ? part.raw_sum_sq().data() : nullptr))
    throw std::overflow_error("reduce_film: a pixel sum or sample count overflows");
}

uint64_t chunk_size(uint64_t remaining, uint64_t probe, double rate, double total_rate) {
  if (remaining == 0) return 0;
  // Not measured yet: the rank's probe (small enough that a CPU rank's first chunk does
  // not outlast a GPU's whole frame, large enough to measure a GPU's rate). Then a fraction f of what is left, shared
  // by rate: every rank's chunk ends after about f of the frame's remaining time, whoever
  // it is, so ranks finish close together. f grows from 3/4 with the rank's share of the
  // rate, so that a dominant rank (a GPU beside CPUs, whose every call costs kernel
  // launches and a partly idle device at its end) needs few chunks, and slow ranks take
  // the smaller ones at the end.
  // Never less than the probe: below it a GPU's call costs more than its samples (a
  // partly idle device, a launch, a sync), so the last crumbs go in one chunk.
  const double share = rate > 0 && total_rate > 0 ? std::min(1.0, rate / total_rate) : 0.0;
  // A rank with nearly all of the rate (the others together under 2 %: a GPU beside CPU
  // ranks) takes all that is left: the others could save at most that share of the frame,
  // less than a further call costs the dominant device, and their probes end within its
  // frame. So a hybrid frame is never slower than the GPU alone (issue 30).
  if (share >= kDominantShare) return remaining;
  const double least = double(std::max<uint64_t>(probe, 1));
  const double want = share > 0 ? std::max(std::ceil((0.75 + 0.2 * share) * share * double(remaining)), least) : least;
  return uint64_t(std::min<double>(want, double(remaining)));
}

}  // namespace pb::run
