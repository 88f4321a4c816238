// The image does not depend on how the work is scheduled: pixel-parallel and
// ray-parallel (wavefront) renders with the same seed and settings give bit-identical
// films -- every int64 fixed-point sum and every sample count -- at 1, 2 and all
// threads and at any number of paths in flight. This is what the counter-based random
// stream and the fixed-point film promise (DESIGN.md, "One random stream"). Different
// seeds give different images.
#include <gtest/gtest.h>

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"

namespace pb {
namespace {

struct Rendered {
  Film film;
  RunReport report;
};

Rendered render_cornell(const RenderSettings& s) {
  static const Scene scene = make_paper_cornell();
  Rendered r{Film(s.width, s.height, s.variance), {}};
  run::render(scene, s, r.film, r.report);
  return r;
}

RenderSettings base_settings(Sampling sampling, int bounces) {
  RenderSettings s;
  s.width = s.height = 64;
  s.spp = 16;
  s.sampling = sampling;
  s.max_bounces = bounces;
  s.russian_roulette = bounces < 0;
  s.seed = 2015;
  s.progress = false;
  return s;
}

std::string describe(const RenderSettings& s) {
  return std::string(to_string(s.strategy)) + ", threads " + std::to_string(s.threads) + ", paths in flight " +
         std::to_string(s.paths_in_flight);
}

// Every fixed-point sum and count identical; reports the first difference.
void expect_identical(const Film& a, const Film& b, const std::string& what) {
  ASSERT_EQ(a.scale(), b.scale()) << what;
  ASSERT_EQ(a.raw_sums().size(), b.raw_sums().size()) << what;
  size_t differing = 0, first = 0;
  for (size_t i = 0; i < a.raw_sums().size(); ++i)
    if (a.raw_sums()[i] != b.raw_sums()[i] && differing++ == 0) first = i;
  EXPECT_EQ(differing, 0u) << what << ": " << differing << " of " << a.raw_sums().size()
                           << " sums differ, first at pixel " << first / 3 << " channel " << first % 3 << " ("
                           << a.raw_sums()[first] << " vs " << b.raw_sums()[first] << ")";
  EXPECT_TRUE(a.counts() == b.counts()) << what << ": sample counts differ";
}

struct StrategyCase {
  const char* name;
  Sampling sampling;
  int bounces;  // -1: unbounded with Russian roulette
};

void PrintTo(const StrategyCase& c, std::ostream* os) { *os << c.name; }

class StrategiesAgree : public ::testing::TestWithParam<StrategyCase> {};

TEST_P(StrategiesAgree, BitIdenticalFilms) {
  const RenderSettings base = base_settings(GetParam().sampling, GetParam().bounces);
  RenderSettings ref_settings = base;
  ref_settings.strategy = Strategy::Pixel;
  ref_settings.threads = 1;
  const Rendered ref = render_cornell(ref_settings);

  // The reference itself: every pixel got exactly spp samples, none discarded.
  const uint64_t total = uint64_t(base.width) * base.height * base.spp;
  EXPECT_EQ(ref.report.paths, total);
  EXPECT_EQ(ref.report.discarded_samples, 0u);
  for (size_t p = 0; p < ref.film.counts().size(); ++p)
    ASSERT_EQ(ref.film.counts()[p], base.spp) << "pixel " << p;
  // Not a black image (uniform sampling at 16 spp leaves many pixels unlit).
  size_t lit = 0;
  for (size_t p = 0; p < ref.film.pixels(); ++p)
    lit += ref.film.raw_sums()[p * 3] != 0 || ref.film.raw_sums()[p * 3 + 1] != 0 || ref.film.raw_sums()[p * 3 + 2] != 0;
  EXPECT_GT(lit, ref.film.pixels() / 4) << "the image is mostly black";

  std::vector<RenderSettings> variants;
  for (int threads : {1, 2, 0}) {
    RenderSettings s = base;
    s.threads = threads;
    s.strategy = Strategy::Pixel;
    if (threads != 1) variants.push_back(s);
    s.strategy = Strategy::Wavefront;
    for (uint64_t pif : {uint64_t(16), uint64_t(1000), uint64_t(0)}) {
      s.paths_in_flight = pif;
      variants.push_back(s);
    }
  }
  // A pool smaller than a packet and one larger than the whole image.
  RenderSettings s = base;
  s.strategy = Strategy::Wavefront;
  s.threads = 2;
  s.paths_in_flight = 3;
  variants.push_back(s);
  s.paths_in_flight = total + 17;
  variants.push_back(s);

  for (const RenderSettings& v : variants) {
    const Rendered r = render_cornell(v);
    SCOPED_TRACE(describe(v));
    EXPECT_EQ(r.report.paths, total);
    EXPECT_EQ(r.report.discarded_samples, 0u);
    EXPECT_EQ(r.report.rays.total(), ref.report.rays.total()) << "the same paths trace the same rays";
    for (size_t p = 0; p < r.film.counts().size(); ++p)
      ASSERT_EQ(r.film.counts()[p], base.spp) << "pixel " << p;
    expect_identical(ref.film, r.film, describe(v));
  }
}

INSTANTIATE_TEST_SUITE_P(PaperCornell, StrategiesAgree,
                         ::testing::Values(StrategyCase{"nee_2", Sampling::Nee, 2},
                                           StrategyCase{"uniform_2", Sampling::Uniform, 2},
                                           StrategyCase{"cosine_5", Sampling::Cosine, 5},
                                           StrategyCase{"nee_unbounded_rr", Sampling::Nee, -1}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(Strategies, VarianceFilmsAgreeToo) {
  // The per-pixel squares are plain doubles, added in sample order per pixel by the
  // pixel strategy but in any order by the wavefront: equal up to rounding only.
  RenderSettings s = base_settings(Sampling::Nee, 2);
  s.width = s.height = 32;
  s.variance = true;
  s.strategy = Strategy::Pixel;
  const Rendered a = render_cornell(s);
  s.strategy = Strategy::Wavefront;
  s.paths_in_flight = 100;
  const Rendered b = render_cornell(s);
  expect_identical(a.film, b.film, "with variance");
  const auto va = a.film.variance_of_mean(), vb = b.film.variance_of_mean();
  ASSERT_EQ(va.size(), vb.size());
  for (size_t i = 0; i < va.size(); ++i) ASSERT_NEAR(va[i], vb[i], 1e-6 * (1 + va[i])) << "value " << i;
}

TEST(Strategies, DifferentSeedsGiveDifferentImages) {
  for (Strategy strategy : {Strategy::Pixel, Strategy::Wavefront}) {
    RenderSettings s = base_settings(Sampling::Nee, 2);
    s.strategy = strategy;
    const Rendered a = render_cornell(s);
    std::vector<uint64_t> seeds = {s.seed + 1, s.seed + (uint64_t(1) << 32)};  // low and high seed words
    for (uint64_t seed : seeds) {
      s.seed = seed;
      const Rendered b = render_cornell(s);
      size_t differing = 0, pixels = a.film.pixels();
      for (size_t p = 0; p < pixels; ++p) {
        bool differs = false;
        for (int c = 0; c < 3; ++c) differs |= a.film.raw_sums()[p * 3 + c] != b.film.raw_sums()[p * 3 + c];
        differing += differs;
      }
      // Only pixels that see nothing but the light (exactly 10 in every sample) agree.
      EXPECT_GT(differing, pixels * 9 / 10) << to_string(strategy) << ", seed " << seed << ": only " << differing
                                           << " of " << pixels << " pixels differ";
      EXPECT_TRUE(a.film.counts() == b.film.counts());
    }
  }
}

TEST(Strategies, SameSeedTwiceIsIdentical) {
  RenderSettings s = base_settings(Sampling::Uniform, 2);
  s.strategy = Strategy::Wavefront;
  s.threads = 0;
  expect_identical(render_cornell(s).film, render_cornell(s).film, "wavefront, run twice");
}

// --paths-in-flight is clamped to the frame's samples: 10^8 paths for 64 samples once
// allocated 10 GB. The pool then holds at most a packet per thread.
TEST(Strategies, PathsInFlightClampedToTheFrame) {
  RenderSettings s = base_settings(Sampling::Nee, 2);
  s.width = s.height = 8;
  s.spp = 1;
  s.threads = 2;
  s.strategy = Strategy::Wavefront;
  s.paths_in_flight = 100000000;
  const Rendered r = render_cornell(s);
  EXPECT_EQ(r.report.paths, s.total_samples());
  EXPECT_LT(r.report.paths_in_flight, 100000u) << "the pool was sized by the setting, not the frame";
}

}  // namespace
}  // namespace pb
