// The run layer (run/): it sizes and begins the film and fills the common report
// fields itself, refuses bad settings before any tracing, and its rank helpers split
// samples and reduce films exactly.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/run/built_scene.h"
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

// run::BuiltScene (built_scene.h: the suite's benchmarks, issue 28): frames on a scene built once
// are run::render's for the same settings (film bit for bit, rays, report fields), frame after
// frame and for other frame settings it serves; settings that need another build are refused,
// and bad settings before anything is built.
TEST(BuiltScene, FramesAreRendersWithoutTheBuild) {
  const Scene scene = make_paper_cornell();
  const RenderSettings s = tiny();
  const run::BuiltScene prepared(scene, s);
  EXPECT_GE(prepared.build_seconds(), 0.0);
  const run::Rendered want = run::render(scene, s);
  Film film;
  for (int frame = 0; frame < 2; ++frame) {
    RunReport r;
    prepared.render(s, film, r);
    EXPECT_EQ(film.raw_sums(), want.film.raw_sums());
    EXPECT_EQ(r.extra["film_hash"], want.report.extra["film_hash"]);
    EXPECT_EQ(r.rays.total(), want.report.rays.total());
    EXPECT_EQ(r.scene, scene.name);
    EXPECT_EQ(r.triangles, scene.triangles.size());
  }
  // Another frame size, sample count and sampling on the same structure.
  RenderSettings other = s;
  other.width = 16;
  other.spp = 2;
  other.sampling = Sampling::Uniform;
  ASSERT_TRUE(prepared.serves(other));
  RunReport r;
  prepared.render(other, film, r);
  EXPECT_EQ(film.width(), 16u);
  EXPECT_EQ(film.raw_sums(), run::render(scene, other).film.raw_sums());
  // A structure of another kind is not there.
  RenderSettings quads = s;
  quads.embree_layout = EmbreeLayout::Quads;
  EXPECT_FALSE(prepared.serves(quads));
  EXPECT_THROW(prepared.render(quads, film, r), std::logic_error);
}

TEST(BuiltScene, RefusesBadSettingsBeforeBuilding) {
  const Scene scene = make_paper_cornell();
  RenderSettings s = tiny();
  s.spp = 0;
  EXPECT_THROW(run::BuiltScene(scene, s), InputError);
}

}  // namespace
}  // namespace pb
