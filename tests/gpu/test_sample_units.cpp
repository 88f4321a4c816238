// The pixel megakernel's units of samples (bvh/sample_units.h): every sample of a launch in
// exactly one unit, a unit never crossing a pixel where its samples are ordered, and the
// first bounce's bins spread over all 16. Plain C++ (label unit); the device's ordering of each
// unit is checked by the films (test_gpu.cpp, GpuPixelLaneOrder: the ordered kernels' films
// equal the 3-block kernel's in sample order, bit for bit; GpuStrategies' small frames do not
// reach the ordered kernels).
#include <gtest/gtest.h>

#include <vector>

#include "pathbench/bvh/sample_units.h"

namespace pb::bvh {
namespace {

TEST(SampleUnits, CoverEverySampleOnceWithinAPixel) {
  for (uint32_t spp : {1u, 31u, 32u, 100u, 127u, 128u, 256u, 300u, 800u, 1000u}) {
    for (uint64_t total : {uint64_t(0), uint64_t(1), uint64_t(spp) * 7, uint64_t(spp) * 7 - 5, uint64_t(spp) * 9 + 33}) {
      SCOPED_TRACE(::testing::Message() << "spp " << spp << " total " << total);
      const uint64_t units = sample_units(total, spp);
      std::vector<int> seen(total, 0);
      uint64_t next = 0;
      for (uint64_t k = 0; k < units; ++k) {
        const SampleUnit u = sample_unit(total, spp, k);
        ASSERT_GT(u.count, 0u);
        ASSERT_EQ(u.g0, next);  // in order, no gap
        next = u.g0 + u.count;
        ASSERT_LE(next, total);
        for (uint64_t g = u.g0; g < next; ++g) ++seen[g];
        if (order_samples(spp)) {
          EXPECT_LE(u.count, kOrderGroup);
          EXPECT_EQ(u.g0 / spp, (next - 1) / spp);  // one pixel
        } else {
          EXPECT_LE(u.count, 32u);
        }
      }
      EXPECT_EQ(next, total);
      for (uint64_t g = 0; g < total; ++g) ASSERT_EQ(seen[g], 1) << g;
    }
  }
}

TEST(SampleUnits, FirstBounceBinsSpreadOverAllCells) {
  std::vector<int> bins(kOrderBins, 0);
  for (uint32_t pixel : {0u, 12345u}) {
    for (uint32_t s = 0; s < 1600; ++s) {
      const uint32_t b = first_bounce_bin(pixel, 0, s);
      ASSERT_LT(b, kOrderBins);
      ++bins[b];
    }
  }
  for (uint32_t b = 0; b < kOrderBins; ++b) EXPECT_GT(bins[b], 3200 / 16 / 2) << b;  // 200 expected
  // The bin is the cell of path_hit's draw at vertex 1 (u0, u1), in Morton order.
  const Uniform4 u = RngStream{7, 0}.draw(3, 1, kRngVertex);
  const uint32_t x = uint32_t(u.v[0] * 4), y = uint32_t(u.v[1] * 4);
  EXPECT_EQ(first_bounce_bin(7, 0, 3), (y >> 1) * 8 + (x >> 1) * 4 + (y & 1) * 2 + (x & 1));
}

}  // namespace
}  // namespace pb::bvh
