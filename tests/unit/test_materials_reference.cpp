// Mirrors, glass and rough metal against Mitsuba 3: the cornell-box variants
// `cornell-box:ggx` (GGX rough conductor) and `cornell-box:spheres` (mirror and glass
// spheres), 64 x 64, 4 bounces, light sampling + MIS, compared per pixel with
// independent Mitsuba references (tests/data/cornell-box-*-nee-ref*.pfm, made by
// tools/make_reference.py; see tests/data/README.md)
// by the same statistical test as test_statistical_render.cpp. Negative controls: a
// GGX alpha of 0.3 instead of 0.2, and glass of ior 1.33 instead of 1.5, are rejected.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "pathbench/scene_io/scene_library.h"
#include "reference_test.h"

namespace pb {
namespace {

#if PATHBENCH_EXTRA_MATERIALS

constexpr uint32_t kSize = 64;
constexpr uint32_t kSpp = 1024;
constexpr int kBounces = 4;                // Mitsuba max_depth 5
constexpr double kMinShare = 0.99;         // of pixel-channels passing
constexpr double kMaxMeanError = 0.01;     // per-channel image mean vs the reference

using reftest::data_path;
using Image = reftest::Image;

Image reference(const std::string& variant) {
  return reftest::load_reference("cornell-box-" + variant + "-nee-ref", kSize);
}

Image render(const Scene& scene, uint64_t seed = 1) {
  RenderSettings s;
  s.width = s.height = kSize;
  s.spp = kSpp;
  s.max_bounces = kBounces;
  s.sampling = Sampling::Nee;
  s.strategy = Strategy::Wavefront;
  s.seed = seed;
  return reftest::render_with_variance(scene, s);
}

using reftest::compare;
bool accepts(const stat::ImageTest& t) { return reftest::accepts(t, kMinShare, kMaxMeanError); }

void print(const std::string& what, const stat::ImageTest& t) {
  std::printf("[ stat     ] %s: %s -> %s\n", what.c_str(), t.summary().c_str(), accepts(t) ? "ACCEPTED" : "REJECTED");
}

class MaterialsReference : public ::testing::TestWithParam<std::string> {};

TEST_P(MaterialsReference, MatchesMitsuba) {
  const std::string variant = GetParam();
  ASSERT_TRUE(std::filesystem::exists(data_path("cornell-box-" + variant + "-nee-ref.pfm")))
      << "missing reference (tools/make_reference.py --scene cornell-box:" << variant << " --bounces 4 --size 64)";
  const stat::ImageTest t = compare(render(make_cornell_box(variant)), reference(variant));
  print("cornell-box:" + variant + " vs Mitsuba 3", t);
  EXPECT_GE(t.share_passed(), kMinShare) << t.summary();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(t.mean_ratio(c), 1.0, kMaxMeanError) << "channel " << "RGB"[c];
  EXPECT_GT(t.zero_variance, 0u) << "no pixel saw only the light: is the image upside down?";
  EXPECT_EQ(t.zero_variance_failed, 0u);
}

INSTANTIATE_TEST_SUITE_P(Variants, MaterialsReference, ::testing::Values("ggx", "spheres"));

// The test can tell a material parameter changed.
TEST(MaterialsReferenceControls, RejectsOtherParameters) {
  for (const char* variant : {"ggx", "spheres"}) {
    if (!std::filesystem::exists(data_path(std::string("cornell-box-") + variant + "-nee-ref.pfm"))) GTEST_SKIP();
    Scene scene = make_cornell_box(variant);
    for (Material& m : scene.materials) {
      if (m.kind == MaterialKind::RoughConductor) m.alpha = 0.3f;
      if (m.kind == MaterialKind::Dielectric) m.ior = 1.33f;
    }
    scene.finalize();
    const stat::ImageTest t = compare(render(scene), reference(variant));
    print(std::string("negative control: cornell-box:") + variant + " with other alpha / ior", t);
    EXPECT_FALSE(accepts(t)) << t.summary();
  }
}

#endif  // PATHBENCH_EXTRA_MATERIALS

}  // namespace
}  // namespace pb
