// The CPU wavefront's sample hand-out (cpu/src/wavefront_pool.h, SampleSource): samples in
// groups of a packet's width per pixel. Whatever the group, the claim sizes, a band of
// pixels (first_pixel > 0), an spp that is not a multiple of the group, or a first sample
// other than 0, every (pixel, sample) of the range is handed out exactly once, and the
// cursor's steps agree with where each index lies.
#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "wavefront_pool.h"

namespace pb::cpu {
namespace {

void expect_each_once(uint32_t first_pixel, uint32_t pixels, uint32_t spp, uint32_t first_sample, uint32_t group,
                      uint64_t claim_size) {
  SCOPED_TRACE(::testing::Message() << "pixels " << first_pixel << "+" << pixels << ", spp " << spp << " from "
                                    << first_sample << ", group " << group << ", claims of " << claim_size);
  SampleSource src(first_pixel, pixels, spp, first_sample, group);
  std::set<std::pair<uint32_t, uint32_t>> seen;
  for (;;) {
    uint64_t n = claim_size;
    const uint64_t start = src.claim(n);
    if (n == 0) break;
    SampleSource::Cursor c = src.at(start);
    for (uint64_t i = 0; i < n; ++i, src.step(c)) {
      const SampleSource::Cursor fresh = src.at(start + i);  // stepping = looking up
      ASSERT_EQ(c.pixel, fresh.pixel);
      ASSERT_EQ(c.sample, fresh.sample);
      ASSERT_GE(c.pixel, first_pixel);
      ASSERT_LT(c.pixel, first_pixel + pixels);
      ASSERT_GE(c.sample, first_sample);
      ASSERT_LT(c.sample, first_sample + spp);
      ASSERT_TRUE(seen.insert({c.pixel, c.sample}).second) << "pixel " << c.pixel << " sample " << c.sample << " twice";
    }
  }
  EXPECT_EQ(seen.size(), size_t(pixels) * spp);
}

TEST(SampleSource, EveryPixelSampleOnceInGroups) {
  for (uint32_t group : {1u, 8u, 16u})
    for (uint64_t claim : {uint64_t(1), uint64_t(7), uint64_t(64), uint64_t(1000)}) {
      expect_each_once(0, 35, 37, 0, group, claim);     // spp 37: groups cut short
      expect_each_once(96, 24, 16, 0, group, claim);    // a band of the frame
      expect_each_once(5, 13, 5, 11, group, claim);     // fewer samples than a group, from sample 11
    }
}

TEST(SampleSource, OnePixelsSamplesComeTogether) {
  SampleSource src(0, 4, 32, 0, 16);
  SampleSource::Cursor c = src.at(0);
  for (uint32_t i = 0; i < 16; ++i, src.step(c)) {
    EXPECT_EQ(c.pixel, 0u);
    EXPECT_EQ(c.sample, i);
  }
  EXPECT_EQ(c.pixel, 1u);
  EXPECT_EQ(c.sample, 0u);
}

}  // namespace
}  // namespace pb::cpu
