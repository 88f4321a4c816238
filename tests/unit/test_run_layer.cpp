// The run layer (run/): it sizes and begins the film and fills the common report
// fields itself, refuses bad settings before any tracing, and its rank helpers split
// samples and reduce films exactly.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/run.h"

namespace pb {
namespace {

RenderSettings tiny() {
  RenderSettings s;
  s.width = 12;
  s.height = 8;
  s.spp = 4;
  s.threads = 1;
  s.progress = false;
  s.embree_layout = EmbreeLayout::Triangles;
  return s;
}

TEST(RunLayer, SizesAndBeginsTheFilmAndFillsTheCommonFields) {
  const Scene scene = make_paper_cornell();
  Film film(3, 3, false);  // wrong size: the run layer sizes it
  RunReport report;
  run::render(scene, tiny(), film, report);
  EXPECT_EQ(film.width(), 12u);
  EXPECT_EQ(film.height(), 8u);
  EXPECT_EQ(film.scale(), Film::choose_scale(4, scene.max_emission()));
  for (uint32_t c : film.counts()) EXPECT_EQ(c, 4u);
  EXPECT_EQ(report.scene, scene.name);
  EXPECT_EQ(report.triangles, scene.triangles.size());
  EXPECT_EQ(report.settings.width, 12u);
  EXPECT_GT(report.peak_host_bytes, 0u);
  EXPECT_EQ(report.paths, 12u * 8u * 4u);

  // The same render through the returning form: the same film, bit for bit.
  const run::Rendered again = run::render(scene, tiny());
  EXPECT_EQ(again.film.raw_sums(), film.raw_sums());
}

TEST(RunLayer, RefusesBadSettingsBeforeTracing) {
  const Scene scene = make_paper_cornell();
  RenderSettings s = tiny();
  s.spp = 0;
  Film film;
  RunReport report;
  EXPECT_THROW(run::render(scene, s, film, report), InputError);
  EXPECT_EQ(film.width(), 0u);  // nothing sized, nothing traced
  EXPECT_TRUE(report.scene.empty());
}

TEST(RunRanks, SharesCoverEverySampleOnce) {
  for (uint32_t ranks : {1u, 2u, 3u, 7u}) {
    for (uint32_t spp : {1u, 5u, 16u, 1000u}) {
      uint32_t next = 0;
      for (uint32_t r = 0; r < ranks; ++r) {
        const run::SampleShare sh = run::share_of(r, ranks, spp);
        EXPECT_EQ(sh.first, next) << ranks << " ranks, " << spp << " spp";
        EXPECT_LE(sh.count, spp / ranks + 1);
        next += sh.count;
      }
      EXPECT_EQ(next, spp);
    }
  }
  EXPECT_THROW(run::share_of(2, 2, 8), std::invalid_argument);
  EXPECT_THROW(run::share_of(0, 0, 8), std::invalid_argument);
}

TEST(RunRanks, ReducesFilmsExactlyAndChecksOverflow) {
  Film a(2, 1, true), b(2, 1, true);
  a.begin(8, 1.0f);
  b.begin(8, 1.0f);
  a.add(0, {0.25f, 0.5f, 1.0f});
  b.add(0, {0.75f, 0.5f, 0.0f});
  b.add(1, {2.0f, 2.0f, 2.0f});
  Film both(2, 1, true);
  both.begin(8, 1.0f);
  both.add(0, {0.25f, 0.5f, 1.0f});
  both.add(0, {0.75f, 0.5f, 0.0f});
  both.add(1, {2.0f, 2.0f, 2.0f});
  run::reduce_film(a, b);
  EXPECT_EQ(a.raw_sums(), both.raw_sums());
  EXPECT_EQ(a.counts(), both.counts());
  EXPECT_EQ(a.raw_sum_sq(), both.raw_sum_sq());

  Film other_scale(2, 1, true);
  other_scale.begin(1024, 1.0f);
  EXPECT_THROW(run::reduce_film(a, other_scale), std::invalid_argument);
  Film big(2, 1, true), more(2, 1, true);
  big.begin(8, 1.0f);
  more.begin(8, 1.0f);
  big.raw_sums()[0] = std::numeric_limits<int64_t>::max() - 1;
  more.raw_sums()[0] = 2;
  EXPECT_THROW(run::reduce_film(big, more), std::overflow_error);
}

}  // namespace
}  // namespace pb
