// The slab test's far end on the host (bvh/hit_tests.h slab_far: the exit widened by
// kFarUlps units in the last place on the floats' bits, clamped to t). What the traversals
// rely on: it is never narrower than Ize's 1 + 2 gamma(3) (the product it replaced), never
// beyond t, and a negative exit (-0 included) stays a miss. The device's form (one DPX
// instruction) is checked against this one ray by ray in test_gpu_slab.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "pathbench/bvh/hit_tests.h"

namespace pb::bvh {
namespace {

using detail::slab_far;
constexpr float kInf = std::numeric_limits<float>::infinity();

// Ize 2013's widening, 1 + 2 gamma(3) = 1 + 6u (u = 2^-24), in double: the least a far end
// may be widened to.
double ize_far(float exit) { return double(exit) * (1.0 + 6.0 * 0x1p-24); }

TEST(SlabFar, WidensAtLeastIzesBoundAtEveryMagnitude) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> mantissa(1.0f, 2.0f);
  std::uniform_int_distribution<int> exponent(-126, 126);
  int checked = 0;
  for (int i = 0; i < 200000; ++i) {
    const float exit = std::ldexp(mantissa(rng), exponent(rng));
    if (!std::isfinite(exit)) continue;
    const float far = slab_far(exit, kInf);
    ASSERT_GE(double(far), ize_far(exit)) << exit;
    ASSERT_GE(far, exit * 1.0000004f) << exit;  // the product it replaced, rounded
    ASSERT_LE(double(far), double(exit) * (1.0 + 12.0 * 0x1p-24)) << exit;  // and not much more
    ++checked;
  }
  EXPECT_GT(checked, 190000);
  // Just below powers of two, where an ulp is the least part of a float (2^-24 of it).
  for (int e = -120; e <= 120; ++e) {
    const float exit = std::nextafter(std::ldexp(1.0f, e), 0.0f);
    EXPECT_GE(double(slab_far(exit, kInf)), ize_far(exit)) << exit;
  }
}

TEST(SlabFar, ClampedToTheBestDistance) {
  EXPECT_EQ(slab_far(2.0f, 1.0f), 1.0f);
  EXPECT_EQ(slab_far(1.0f, 1.0f), 1.0f);
  EXPECT_GT(slab_far(1.0f, 2.0f), 1.0f);
  EXPECT_LT(slab_far(1.0f, 2.0f), 2.0f);
  EXPECT_EQ(slab_far(kInf, 5.0f), 5.0f);  // +inf's bits and 6 more: above every finite t
  EXPECT_EQ(slab_far(kInf, kInf), kInf);
  EXPECT_EQ(slab_far(std::numeric_limits<float>::max(), 3.0f), 3.0f);
  EXPECT_GT(slab_far(0.0f, 1.0f), 0.0f);  // an exit at +0: the box is entered at 0
}

TEST(SlabFar, NegativeExitsStayMisses) {
  // The entry is >= +0 (slab_entry), so tn <= tf fails for every negative tf.
  for (float exit : {-0.0f, -std::numeric_limits<float>::denorm_min(), -1e-30f, -1.0f, -3e38f, -kInf}) {
    const float far = slab_far(exit, 10.0f);
    EXPECT_TRUE(std::signbit(far)) << exit;  // -inf's bits and 6 more: a negative NaN
    EXPECT_FALSE(0.0f <= far) << exit;
  }
}

}  // namespace
}  // namespace pb::bvh
