// Issue 13 without MPI: the tracers trace any sample range of every pixel, so films of
// a split frame reduce to the whole frame's film bit for bit (the ground MPI ranks stand
// on), and the rank render's grant rule and report arithmetic.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/ranks_render.h"
#include "pathbench/run/ranks_report.h"
#include "pathbench/run/run.h"
#include "pathbench/run/world.h"

namespace pb {
namespace {

RenderSettings small(Strategy strategy, Isa isa) {
  RenderSettings s;
  s.width = 16;
  s.height = 12;
  s.spp = 11;
  s.threads = 2;
  s.progress = false;
  s.strategy = strategy;
  s.isa = isa;
  s.embree_layout = EmbreeLayout::Triangles;
  return s;
}

// Films of the ranges in `cuts` (sample indices), reduced, against one film of the frame.
void expect_split_equals_whole(const RenderSettings& whole, const std::vector<uint32_t>& cuts) {
  const Scene scene = make_paper_cornell();
  const run::Rendered one = run::render(scene, whole);
  Film sum;
  uint64_t paths = 0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    RenderSettings s = whole;
    s.first_sample = cuts[i];
    s.sample_count = cuts[i + 1] - cuts[i];
    run::Rendered part = run::render(scene, s);
    paths += part.report.paths;
    if (i == 0) sum = std::move(part.film);
    else run::reduce_film(sum, part.film);
  }
  EXPECT_EQ(paths, one.report.paths);
  EXPECT_EQ(sum.counts(), one.film.counts());
  EXPECT_EQ(sum.raw_sums(), one.film.raw_sums());  // bit for bit, not "close"
}

TEST(RankSplit, PixelStrategyAnySplitGivesTheSameFilm) {
  expect_split_equals_whole(small(Strategy::Pixel, Isa::Auto), {0, 3, 4, 11});
  expect_split_equals_whole(small(Strategy::Pixel, Isa::Scalar), {0, 5, 11});
}

TEST(RankSplit, WavefrontStrategyAnySplitGivesTheSameFilm) {
  expect_split_equals_whole(small(Strategy::Wavefront, Isa::Auto), {0, 1, 2, 9, 11});
  expect_split_equals_whole(small(Strategy::Wavefront, Isa::Scalar), {0, 6, 11});
}

TEST(RankSplit, RangeOutsideTheFrameIsABug) {
  RenderSettings s = small(Strategy::Pixel, Isa::Auto);
  s.first_sample = 10;
  s.sample_count = 2;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s.first_sample = 11;
  s.sample_count = 0;
  EXPECT_THROW(s.validate(), std::invalid_argument);
}

TEST(RankSplit, ChunksFollowTheRateAndCoverTheFrame) {
  // Unmeasured: a probe of one sample per pixel.
  EXPECT_EQ(run::chunk_size(1024, 1024, 2, 0, 0), 1u);
  // A rank with 3/4 of the total rate gets (3/4 + 0.2 x 3/4) x 3/4 of what is left.
  EXPECT_EQ(run::chunk_size(800, 1024, 2, 3.0, 4.0), 540u);
  // Never more than is left, never less than one.
  EXPECT_EQ(run::chunk_size(5, 1024, 2, 100.0, 100.0), 5u);
  EXPECT_EQ(run::chunk_size(500, 1024, 2, 1.0, 1000.0), 1u);
  EXPECT_EQ(run::chunk_size(0, 1024, 2, 1.0, 1.0), 0u);
  // A GPU 30x a CPU, each asking when its chunk would end: the frame is covered exactly,
  // the GPU needs few chunks, and the CPU's work ends no later than the GPU's.
  const double rate[2] = {30.0, 1.0};
  double busy_until[2] = {0, 0};
  uint32_t next = 0, chunks[2] = {0, 0};
  while (next < 1024) {
    const int r = busy_until[0] <= busy_until[1] ? 0 : 1;
    const uint32_t c = run::chunk_size(1024 - next, 1024, 2, rate[r], 31.0);
    ASSERT_GT(c, 0u);
    next += c;
    busy_until[r] += c / rate[r];
    ++chunks[r];
  }
  EXPECT_EQ(next, 1024u);
  EXPECT_LE(chunks[0], 6u);
  EXPECT_LE(busy_until[1], busy_until[0] * 1.05);
}

TEST(RankSplit, OneProcessIsOneRank) {
  run::World& w = run::World::get();
  EXPECT_EQ(w.size(), 1);
  EXPECT_TRUE(w.root());
  // Whole-frame dispensing in one rank: everything, then nothing.
  run::SampleDispenser d(w, 9);
  const run::SampleShare a = d.next(0);
  EXPECT_EQ(a.first, 0u);
  EXPECT_EQ(a.count, 9u);
  EXPECT_EQ(d.next(1.0).count, 0u);
  d.finish();
  EXPECT_THROW(run::rank_device("hybrid"), InputError);
  EXPECT_EQ(run::rank_device("cpu"), "cpu");
}

TEST(RankSplit, SettingsKeyIgnoresDeviceAndThreadsOnly) {
  const Scene scene = make_paper_cornell();
  RenderSettings a = small(Strategy::Pixel, Isa::Auto), b = a;
  b.device = Device::Gpu;
  b.threads = 7;
  EXPECT_EQ(run::settings_key(scene, a), run::settings_key(scene, b));
  b.seed = 5;
  const std::string ka = run::settings_key(scene, a), kb = run::settings_key(scene, b);
  EXPECT_NE(ka, kb);
  EXPECT_EQ(run::first_difference(ka, kb), "seed=5 here, seed=0 on rank 0");
  Scene moved = scene;
  moved.positions[0].x += 1e-3f;
  EXPECT_NE(run::settings_key(moved, a), ka);
}

TEST(RankSplit, MergedReportSumsRanksAndMeasuresBalance) {
  RenderSettings s = small(Strategy::Pixel, Isa::Auto);
  RunReport r0, r1;
  r0.rays.camera = 100, r0.paths = 100, r0.seconds = 2.0, r0.threads = 4;
  r1.rays.camera = 50, r1.rays.shadow = 10, r1.paths = 50, r1.seconds = 1.0, r1.threads = 4;
  const std::vector<std::string> entries = {run::rank_entry(0, "a", s, r0, -1, 8, 1, 2.1).dump(),
                                            run::rank_entry(1, "b", s, r1, -1, 3, 2, 2.1).dump()};
  RunReport merged = r0;
  merged.settings = s;
  run::merge_ranks(merged, entries, 2.5, 0.1, "dynamic");
  EXPECT_EQ(merged.rays.total(), 160u);
  EXPECT_EQ(merged.paths, 150u);
  EXPECT_DOUBLE_EQ(merged.seconds, 2.5);
  const nlohmann::json& x = merged.extra["ranks"];
  EXPECT_EQ(x["count"], 2);
  EXPECT_DOUBLE_EQ(x["load_balance"].get<double>(), 2.0 / 1.5);               // max / mean
  EXPECT_DOUBLE_EQ(x["parallel_efficiency"].get<double>(), 3.0 / (2 * 2.5));  // busy / (N x frame)
  EXPECT_DOUBLE_EQ(x["device_share"]["cpu"].get<double>(), 1.0);
  EXPECT_EQ(x["per_rank"][1]["samples_per_pixel"], 3);
}

}  // namespace
}  // namespace pb
