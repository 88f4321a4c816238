#include "pathbench/run/ranks.h"

#include <algorithm>
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

void reduce_film(Film& into, const Film& part) {
  if (into.width() != part.width() || into.height() != part.height() || into.scale() != part.scale() ||
      into.has_variance() != part.has_variance())
    throw std::invalid_argument("reduce_film: the films differ in size, scale or variance");
  auto& sum = into.raw_sums();
  const auto& add = part.raw_sums();
  for (size_t i = 0; i < sum.size(); ++i)
    if (__builtin_add_overflow(sum[i], add[i], &sum[i])) throw std::overflow_error("reduce_film: a pixel sum overflows");
  auto& count = into.counts();
  for (size_t i = 0; i < count.size(); ++i)
    if (__builtin_add_overflow(count[i], part.counts()[i], &count[i]))
      throw std::overflow_error("reduce_film: a pixel's sample count overflows");
  if (into.has_variance()) {
    auto& sq = into.raw_sum_sq();
    const auto& sq_add = part.raw_sum_sq();
    for (size_t i = 0; i < sq.size(); ++i) sq[i] += sq_add[i];
  }
}

uint32_t chunk_size(uint32_t remaining, uint32_t spp, int ranks, double rate, double total_rate) {
  (void)spp, (void)ranks;
  if (remaining == 0) return 0;
  // Not measured yet: a probe of one sample per pixel (a CPU rank's first chunk must not
  // outlast a GPU's whole frame). Then a fraction f of what is left, shared by rate: every
  // rank's chunk ends after about f of the frame's remaining time, whoever it is, so ranks
  // finish close together. f grows from 3/4 with the rank's share of the rate, so that a
  // dominant rank (a GPU beside CPUs, whose every call costs a warm-up frame and a film
  // copy) needs few chunks, and slow ranks take the smaller ones at the end.
  const double share = rate > 0 && total_rate > 0 ? std::min(1.0, rate / total_rate) : 0.0;
  const double want = share > 0 ? std::ceil((0.75 + 0.2 * share) * share * double(remaining)) : 1.0;
  return uint32_t(std::min<double>(std::max(want, 1.0), remaining));
}

}  // namespace pb::run
