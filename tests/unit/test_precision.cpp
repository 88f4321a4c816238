// --precision double: the CPU strategies run the shared path step in double. The
// schedule still does not change the image (pixel and wavefront films bit-identical),
// the path state grows with the scalar, and the image agrees with the float one to
// within rounding: on paper-cornell the two differ only where rounding flips a
// decision (an edge hit, a roulette draw at its threshold).
#include <gtest/gtest.h>

#include <cmath>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"
#include "furnace_check.h"

namespace pb {
namespace {

struct Rendering {
  Film film;
  RunReport report;
};

Rendering render(Precision precision, Strategy strategy) {
  static const Scene scene = make_paper_cornell();
  RenderSettings s;
  s.width = s.height = 32;
  s.spp = 16;
  s.max_bounces = -1;
  s.russian_roulette = true;
  s.precision = precision;
  s.strategy = strategy;
  s.seed = 11;
  s.progress = false;
  Rendering r{Film(s.width, s.height, false), {}};
  run::render(scene, s, r.film, r.report);
  return r;
}

TEST(Precision, DoubleStrategiesGiveBitIdenticalFilms) {
  const Rendering pixel = render(Precision::Double, Strategy::Pixel);
  const Rendering wave = render(Precision::Double, Strategy::Wavefront);
  EXPECT_TRUE(pixel.film.raw_sums() == wave.film.raw_sums());
  EXPECT_EQ(pixel.report.rays.total(), wave.report.rays.total());
  EXPECT_EQ(pixel.report.discarded_samples, 0u);
}

TEST(Precision, DoubleAgreesWithFloatAndCarriesMoreState) {
  for (Strategy strategy : {Strategy::Pixel, Strategy::Wavefront}) {
    SCOPED_TRACE(to_string(strategy));
    const Rendering f = render(Precision::Float, strategy);
    const Rendering d = render(Precision::Double, strategy);
    EXPECT_GT(d.report.state_bytes_per_path, f.report.state_bytes_per_path);
    EXPECT_EQ(d.report.to_json()["precision"], "double");
    EXPECT_EQ(f.report.to_json()["precision"], "float");
    // Not the same bits (the arithmetic differs) ...
    EXPECT_FALSE(f.film.raw_sums() == d.film.raw_sums());
    // ... but the same image: pixel by pixel close, and the image means within 0.1%.
    const std::vector<float> a = f.film.mean(), b = d.film.mean();
    size_t far = 0;
    for (size_t i = 0; i < a.size(); ++i) far += std::fabs(a[i] - b[i]) > 1e-3f * (1.0f + std::fabs(a[i]));
    EXPECT_LT(far, a.size() / 100) << far << " of " << a.size() << " pixel-channels differ by more than 0.1%";
    EXPECT_NEAR(image_mean(d.film).mean, image_mean(f.film).mean, 1e-3 * image_mean(f.film).mean);
  }
}

TEST(Precision, ParsesAndNamesPrecision) {
  EXPECT_EQ(parse_precision("float"), Precision::Float);
  EXPECT_EQ(parse_precision("double"), Precision::Double);
  EXPECT_STREQ(to_string(Precision::Double), "double");
  EXPECT_THROW(parse_precision("half"), InputError);
}

}  // namespace
}  // namespace pb
