#pragma once
// The pixel megakernel's units of work (gpu/src/sample_order.cuh orders each unit's samples
// in a warp): host+device, so that the host tests check that the units cover a launch's
// samples once each.
#include <cstdint>

#include "pathbench/common/hd.h"
#include "pathbench/common/rng.h"

namespace pb::bvh {

constexpr uint32_t kOrderGroup = 256;         // samples of one pixel a warp orders at once (8 chunks)
constexpr uint32_t kOrderBins = 16;           // 4x4 cells of the first bounce's (u0, u1)
constexpr uint32_t kOrderMinSpp = kOrderGroup / 2;  // fewer samples a pixel: chunks of 32 in sample order

// A warp's unit of work: samples [g0, g0 + count) of the launch (sample index g: pixel g / spp,
// sample g % spp), in order, or ordered by first_bounce_bin within one pixel.
struct SampleUnit {
  uint64_t g0;
  uint32_t count;
};

// Ordered: units are groups of up to kOrderGroup samples that never cross a pixel; else chunks
// of 32 consecutive samples (small spp: a group would hold too few samples to order).
PB_HD bool order_samples(uint32_t spp) { return spp >= kOrderMinSpp; }
// Ordered units a pixel's samples take (the last one may be short).
PB_HD uint64_t units_per_pixel(uint32_t spp) { return (uint64_t(spp) + kOrderGroup - 1) / kOrderGroup; }
PB_HD uint64_t sample_units(uint64_t total, uint32_t spp) {
  if (!order_samples(spp)) return (total + 31) / 32;
  return total / spp * units_per_pixel(spp) + units_per_pixel(uint32_t(total % spp));
}
PB_HD SampleUnit sample_unit(uint64_t total, uint32_t spp, uint64_t k) {
  uint64_t g0 = k * 32;
  uint32_t most = 32;
  if (order_samples(spp)) {
    const uint64_t per_pixel = units_per_pixel(spp), j = k % per_pixel;
    g0 = k / per_pixel * spp + j * kOrderGroup;
    most = uint32_t(spp - j * kOrderGroup < kOrderGroup ? spp - j * kOrderGroup : kOrderGroup);
  }
  const uint64_t left = total - g0;
  return {g0, uint32_t(left < most ? left : most)};
}

// The cell of the first bounce's BSDF numbers (path_hit's draw at vertex 1: u0, u1), 4x4
// cells in Morton order, so that neighbouring bins are neighbouring cells.
PB_HD uint32_t first_bounce_bin(uint32_t pixel, uint64_t seed, uint32_t sample) {
  const Uniform4 u = RngStream{pixel, seed}.draw(sample, 1, kRngVertex);
  const uint32_t x = uint32_t(u.v[0] * 4.0f), y = uint32_t(u.v[1] * 4.0f);  // u < 1: 0..3
  return (y >> 1) << 3 | (x >> 1) << 2 | (y & 1u) << 1 | (x & 1u);
}

}  // namespace pb::bvh
