// "Same image up to noise", tested the way Mitsuba 3 tests its renders: paper-cornell
// at 256 x 256, 2 bounces, light sampling + MIS, against an independent reference
// rendered by Mitsuba 3 (tests/data/paper-cornell-nee-ref.pfm and its variance image,
// made by tools/make_reference.py; see tests/data/README.md).
//
// For every pixel-channel, z = (ours - ref) / sqrt(var_ours + var_ref) is compared
// with a standard normal, two-sided, at the Sidak-corrected level
// 1 - (1 - 0.01)^(1/N) over all N pixel-channels. The render passes when at least 99 %
// of the pixel-channels pass and the image mean of each channel is within 0.5 % of the
// reference's. Pixels that see only the light (exactly 10 in every sample, zero
// variance in both images) are compared exactly. Negative controls: the same test must
// reject a render with one bounce instead of two, and one whose white walls reflect
// 0.52 instead of 0.5.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "pathbench/scene_io/scene_library.h"
#include "reference_test.h"

namespace pb {
namespace {

constexpr uint32_t kSize = 256;
constexpr uint32_t kSpp = 128;            // ~5-10 s on 2 cores
constexpr double kMinShare = 0.99;        // of pixel-channels passing
constexpr double kMaxMeanError = 0.005;   // per-channel image mean vs the reference

using reftest::data_path;
using Reference = reftest::Image;
using Ours = reftest::Image;

const Reference& reference() {
  static const Reference ref = reftest::load_reference("paper-cornell-nee-ref", kSize);
  return ref;
}

Ours render(const Scene& scene, int bounces, uint64_t seed = 1) {
  RenderSettings s;
  s.width = s.height = kSize;
  s.spp = kSpp;
  s.max_bounces = bounces;
  s.sampling = Sampling::Nee;
  s.strategy = Strategy::Pixel;
  s.seed = seed;
  return reftest::render_with_variance(scene, s);
}

using reftest::compare;
bool accepts(const stat::ImageTest& t) { return reftest::accepts(t, kMinShare, kMaxMeanError); }

void print(const char* what, const stat::ImageTest& t, double seconds) {
  std::printf("[ stat     ] %s (%u spp, %.1f s): %s -> %s\n", what, kSpp, seconds, t.summary().c_str(),
              accepts(t) ? "ACCEPTED" : "REJECTED");
}

bool have_reference() {
  return std::filesystem::exists(data_path("paper-cornell-nee-ref.pfm")) &&
         std::filesystem::exists(data_path("paper-cornell-nee-ref-var.pfm"));
}

TEST(StatisticalRender, PaperCornellNeeMatchesMitsubaReference) {
  ASSERT_TRUE(have_reference()) << "missing tests/data/paper-cornell-nee-ref*.pfm (tools/make_reference.py)";
  const Reference& ref = reference();
  const Ours ours = render(make_paper_cornell(), 2);
  const stat::ImageTest t = compare(ours, ref);
  print("paper-cornell, 2 bounces, nee vs Mitsuba 3", t, ours.seconds);
  EXPECT_GE(t.share_passed(), kMinShare) << t.summary();
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(t.mean_ratio(c), 1.0, kMaxMeanError) << "channel " << "RGB"[c] << ": " << t.summary();
  EXPECT_GT(t.zero_variance, 0u) << "no pixel saw only the light: is the image upside down?";
  EXPECT_EQ(t.zero_variance_failed, 0u) << "directly seen light differs from 10";
}

TEST(StatisticalRender, RejectsOneBounceInsteadOfTwo) {
  ASSERT_TRUE(have_reference());
  const Reference& ref = reference();
  const Ours ours = render(make_paper_cornell(), 1);
  const stat::ImageTest t = compare(ours, ref);
  print("negative control: 1 bounce", t, ours.seconds);
  // Both parts of the test reject it on their own.
  EXPECT_LT(t.share_passed(), kMinShare) << t.summary();
  EXPECT_LT(t.mean_ratio(0), 1 - kMaxMeanError) << t.summary();
  EXPECT_FALSE(accepts(t));
}

TEST(StatisticalRender, RejectsChangedAlbedo) {
  ASSERT_TRUE(have_reference());
  const Reference& ref = reference();
  Scene scene = make_paper_cornell();
  bool changed = false;
  for (size_t i = 0; i < scene.materials.size(); ++i)
    if (scene.material_names[i] == "white") {
      scene.materials[i].albedo = {0.52f, 0.52f, 0.52f};
      changed = true;
    }
  ASSERT_TRUE(changed);
  scene.finalize();
  const Ours ours = render(scene, 2);
  const stat::ImageTest t = compare(ours, ref);
  print("negative control: white albedo 0.52", t, ours.seconds);
  EXPECT_FALSE(accepts(t)) << t.summary();
}

TEST(StatisticalRender, AnotherSeedPassesToo) {
  // The acceptance is not luck of one seed: a second, independent render passes too.
  ASSERT_TRUE(have_reference());
  const Reference& ref = reference();
  const Ours ours = render(make_paper_cornell(), 2, 20150601);
  const stat::ImageTest t = compare(ours, ref);
  print("paper-cornell, seed 20150601", t, ours.seconds);
  EXPECT_TRUE(accepts(t)) << t.summary();
}

}  // namespace
}  // namespace pb
