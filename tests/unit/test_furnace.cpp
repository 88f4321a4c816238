// White furnace: in a closed box whose every wall has albedo a and emission Le, the
// radiance along every ray is known exactly: Le (1 + a + ... + a^k) after k bounces,
// Le / (1 - a) unbounded. Checked for every sampling mode within the noise.
#include <gtest/gtest.h>

#include <cmath>

#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"
#include "furnace_check.h"

namespace pb {
namespace {

struct FurnaceCase {
  Sampling sampling;
  int bounces;  // -1: unbounded with Russian roulette
};

class Furnace : public ::testing::TestWithParam<FurnaceCase> {};

TEST_P(Furnace, MeanMatchesClosedForm) {
  const float a = 0.5f, Le = 1.0f;
  const Scene scene = make_furnace(a, Le);
  RenderSettings s;
  s.width = s.height = 16;
  s.spp = 256;
  s.sampling = GetParam().sampling;
  s.max_bounces = GetParam().bounces;
  s.russian_roulette = s.max_bounces < 0;
  s.rr_start_depth = 1;
  s.variance = true;
  s.progress = false;
  Film film(s.width, s.height, true);
  RunReport report;
  run::render(scene, s, film, report);

  const double expected = furnace_radiance(a, Le, s.max_bounces);
  const auto [measured, sigma] = image_mean(film);
  EXPECT_EQ(report.discarded_samples, 0u);
  EXPECT_EQ(report.paths, uint64_t(s.width) * s.height * s.spp);
  // With a zero-variance estimator (e.g. NEE at 0 bounces) sigma is ~0: allow rounding.
  EXPECT_NEAR(measured, expected, 5 * sigma + 1e-5 * expected)
      << "sampling " << to_string(s.sampling) << ", bounces " << s.max_bounces << ", sigma " << sigma;
}

INSTANTIATE_TEST_SUITE_P(
    AllSamplings, Furnace,
    ::testing::Values(FurnaceCase{Sampling::Uniform, 0}, FurnaceCase{Sampling::Uniform, 1},
                      FurnaceCase{Sampling::Uniform, 2}, FurnaceCase{Sampling::Uniform, 5},
                      FurnaceCase{Sampling::Cosine, 0}, FurnaceCase{Sampling::Cosine, 2},
                      FurnaceCase{Sampling::Cosine, 5}, FurnaceCase{Sampling::Nee, 0},
                      FurnaceCase{Sampling::Nee, 1}, FurnaceCase{Sampling::Nee, 2}, FurnaceCase{Sampling::Nee, 5},
                      FurnaceCase{Sampling::Uniform, -1}, FurnaceCase{Sampling::Cosine, -1},
                      FurnaceCase{Sampling::Nee, -1}),
    [](const auto& info) {
      return std::string(to_string(info.param.sampling)) + "_" +
             (info.param.bounces < 0 ? std::string("unbounded") : std::to_string(info.param.bounces));
    });

}  // namespace
}  // namespace pb
