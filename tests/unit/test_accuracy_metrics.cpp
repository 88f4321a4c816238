// The error metrics of `pathbench accuracy` (app/accuracy_metrics.h) on images with
// known answers: identical images, constant offsets, scaled images, synthetic noise
// of known variance, and a furnace render whose truncation bias is known exactly.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "pathbench/analysis/accuracy_metrics.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"

namespace pb::analysis {
namespace {

// A reference with varied values (a gradient, some black pixels), RGB.
std::vector<float> gradient(size_t pixels) {
  std::vector<float> img(pixels * 3);
  for (size_t i = 0; i < img.size(); ++i) img[i] = (i % 7 == 0) ? 0.0f : 0.05f + float(i % 101) / 40.0f;
  return img;
}

TEST(AccuracyMetrics, IdenticalImagesHaveNoError) {
  const std::vector<float> ref = gradient(64);
  const ImageError e = image_error(ref, ref);
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_EQ(e.rel_mse, 0.0);
  const Bias b = relative_bias(ref, {}, ref, {});
  EXPECT_EQ(b.relative, 0.0);
  EXPECT_EQ(b.std_error, 0.0);
  EXPECT_EQ(b.z(), 0.0);
}

TEST(AccuracyMetrics, ConstantOffsetGivesKnownRmseAndRelativeMse) {
  const std::vector<float> ref = gradient(50);
  const float d = 0.25f;
  std::vector<float> x = ref;
  for (float& v : x) v += d;
  const ImageError e = image_error(x, ref);
  EXPECT_NEAR(e.rmse, d, 1e-6);
  double expected = 0;
  for (float r : ref) expected += double(d) * d / (double(r) * r + kRelMseEpsilon);
  expected /= double(ref.size());
  EXPECT_NEAR(e.rel_mse, expected, 1e-6 * expected);  // x = ref + d is rounded to float
  // eps matters where the reference is black: there the error counts as d^2 / eps.
  const ImageError black = image_error(std::vector<float>(3, d), std::vector<float>(3, 0.0f));
  EXPECT_NEAR(black.rel_mse, d * d / kRelMseEpsilon, 1e-9);
}

TEST(AccuracyMetrics, ScaledImageHasTheScaleAsRelativeBias) {
  const std::vector<float> ref = gradient(100);
  for (double k : {0.5, 0.9, 1.1, 3.0}) {
    std::vector<float> x = ref;
    for (float& v : x) v = float(v * k);
    EXPECT_NEAR(relative_bias(x, {}, ref, {}).relative, k - 1.0, 1e-6) << "scale " << k;
  }
}

TEST(AccuracyMetrics, StandardErrorFromVarianceImages) {
  // Reference 1 everywhere, so sum(ref) = 3N. With variance v in every channel of x and
  // channels taken as fully correlated: Var(sum) = N (3 sqrt(v))^2 and the standard
  // error of the relative bias is sqrt(9 N v) / (3 N) = sqrt(v / N).
  const size_t n = 400;
  const std::vector<float> ref(n * 3, 1.0f), v(n * 3, 0.04f);
  Bias b = relative_bias(ref, v, ref, {});
  EXPECT_NEAR(b.std_error, std::sqrt(0.04 / n), 1e-9);
  // The reference's variance adds (scaled by the ratio, here 1).
  b = relative_bias(ref, v, ref, v);
  EXPECT_NEAR(b.std_error, std::sqrt(2 * 0.04 / n), 1e-9);
  EXPECT_NEAR(rel_mse_floor(ref, v), 0.04 / (1 + kRelMseEpsilon), 1e-9);
}

TEST(AccuracyMetrics, NoiseIsNotBiasButAScaleIs) {
  // Images drawn around the reference with a known per-pixel variance: |z| stays small;
  // the same noise around 1.03 x the reference is flagged.
  const size_t n = 32 * 32;
  const std::vector<float> ref = gradient(n);
  std::vector<float> var(ref.size());
  for (size_t i = 0; i < ref.size(); ++i) var[i] = 0.01f * (ref[i] + 0.1f);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  int unbiased_flagged = 0, biased_flagged = 0;
  double mean_z = 0;
  const int trials = 200;
  for (int t = 0; t < trials; ++t) {
    std::vector<float> x(ref.size()), y(ref.size());
    for (size_t i = 0; i < ref.size(); ++i) {
      const double noise = normal(rng) * std::sqrt(var[i]);
      x[i] = float(ref[i] + noise);
      y[i] = float(1.03 * ref[i] + noise);
    }
    const double z = relative_bias(x, var, ref, {}).z();
    mean_z += z / trials;
    unbiased_flagged += std::fabs(z) > kBiasZThreshold;
    biased_flagged += std::fabs(relative_bias(y, var, ref, {}).z()) > kBiasZThreshold;
  }
  EXPECT_EQ(unbiased_flagged, 0);
  EXPECT_EQ(biased_flagged, trials);
  // Channels are independent here, so the bound overstates the error about sqrt(3)-fold.
  EXPECT_LT(std::fabs(mean_z), 0.2);
}

TEST(AccuracyMetrics, FurnaceTruncationBiasIsMeasured) {
  // A white furnace (albedo a, emission Le) has radiance Le / (1 - a) with unbounded
  // paths and Le (1 + a) with one bounce: a relative bias of (1 + a)(1 - a) - 1 = -a^2.
  const float a = 0.5f, Le = 1.0f;
  const Scene scene = make_furnace(a, Le);
  RenderSettings s;
  s.width = s.height = 16;
  s.spp = 64;
  s.max_bounces = 1;
  s.sampling = Sampling::Cosine;
  s.variance = true;
  s.progress = false;
  Film film(s.width, s.height, true);
  RunReport report;
  run::render(scene, s, film, report);
  const std::vector<float> exact(film.pixels() * 3, Le / (1 - a));
  const Bias b = relative_bias(film.mean(), film.variance_of_mean(), exact, {});
  EXPECT_NEAR(b.relative, -a * a, 4 * b.std_error + 1e-6);
  EXPECT_GT(std::fabs(b.z()), kBiasZThreshold);
}

TEST(AccuracyMetrics, EfficiencyAndBadInput) {
  EXPECT_DOUBLE_EQ(efficiency(0.01, 2.0), 50.0);
  EXPECT_TRUE(std::isinf(efficiency(0.0, 1.0)));
  EXPECT_THROW(image_error(std::vector<float>(6, 1.0f), std::vector<float>(3, 1.0f)), std::invalid_argument);
  EXPECT_THROW(image_error({}, {}), std::invalid_argument);
  EXPECT_THROW(relative_bias(std::vector<float>(3, 1.0f), {}, std::vector<float>(3, 0.0f), {}), std::invalid_argument);
  EXPECT_THROW(relative_bias(std::vector<float>(3, 1.0f), std::vector<float>(6, 1.0f), std::vector<float>(3, 1.0f), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace pb::analysis
