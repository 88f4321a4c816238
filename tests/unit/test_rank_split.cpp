// Issue 13 without MPI: the tracers trace any sample range of every pixel, so films of
// a split frame reduce to the whole frame's film bit for bit (the ground MPI ranks stand
// on), and the rank render's grant rule and report arithmetic.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/ranks_render.h"
#include "pathbench/run/ranks_report.h"
#include "pathbench/run/run.h"
#include "pathbench/run/world.h"
#include "../../run/src/gpu_reduce.h"  // reduction_bands, band_rows (run/ private)

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

// Films of the dynamic chunks `cuts` (unit indices: row-major rows x spp, run/ranks.h)
// traced block by block, reduced row band by row band, against one film of the frame.
void expect_chunks_equal_whole(const RenderSettings& whole, const std::vector<uint64_t>& cuts) {
  const Scene scene = make_paper_cornell();
  const run::Rendered one = run::render(scene, whole);
  Film sum(whole.width, whole.height, false);
  sum.begin(whole.spp, scene.max_emission());
  uint64_t paths = 0;
  const size_t w = whole.width;
  for (size_t i = 0; i + 1 < cuts.size(); ++i)
    for (const run::FrameBlock& b : run::blocks_of({cuts[i], cuts[i + 1] - cuts[i]}, whole.spp, whole.height)) {
      RenderSettings s = whole;
      s.first_row = b.first_row;
      s.row_count = b.rows;
      s.first_sample = b.first_sample;
      s.sample_count = b.samples;
      const run::Rendered part = run::render(scene, s);
      paths += part.report.paths;
      // Only the block's rows are added (as World::reduce_film_rows sends a rank's rows).
      ASSERT_TRUE(run::add_rows_into(sum, b.first_row, b.rows, part.film.raw_sums().data() + b.first_row * w * 3,
                                     part.film.counts().data() + b.first_row * w, nullptr));
    }
  EXPECT_EQ(paths, one.report.paths);
  EXPECT_EQ(sum.counts(), one.film.counts());
  EXPECT_EQ(sum.raw_sums(), one.film.raw_sums());  // bit for bit
}

// Issue 30: CPU ranks of the pixel strategy trace whole batches of kSampleBatch samples at
// absolute batch boundaries, static and dynamic, so that every packet of theirs (W = 16 or 8
// samples of a pixel from the block's first) holds the samples one process's does: Embree's
// packet answer for a ray at an edge depends on its mates. Before, 3 ranks at 800 spp took
// 267 + 267 + 266 samples, and a rank's packets started at sample 267.
TEST(RankSplit, CpuSharesAndChunksAreWholeAlignedBatches) {
  const uint32_t b = run::kSampleBatch;
  ASSERT_EQ(b % 16, 0u) << "a batch must hold whole packets of the widest ISA (AVX-512: 16)";
  auto aligned = [&](uint32_t sample, uint32_t spp) { return sample % b == 0 || sample == spp; };
  std::vector<uint32_t> spps;
  for (uint32_t spp = 1; spp <= 100; ++spp) spps.push_back(spp);
  for (uint32_t spp : {255u, 256u, 267u, 800u, 801u, 1024u}) spps.push_back(spp);
  for (uint32_t spp : spps)
    for (uint32_t ranks = 1; ranks <= 6; ++ranks) {
      uint32_t next = 0, most = 0;
      for (uint32_t r = 0; r < ranks; ++r) {
        const run::SampleShare sh = run::share_of(r, ranks, spp, b);
        EXPECT_EQ(sh.first, next) << spp << " spp, rank " << r << " of " << ranks;
        EXPECT_TRUE(aligned(sh.first, spp) && aligned(sh.first + sh.count, spp))
            << spp << " spp, rank " << r << " of " << ranks << ": samples " << sh.first << " + " << sh.count;
        next = sh.first + sh.count;
        most = std::max(most, sh.count);
        const run::SampleShare one = run::share_of(r, ranks, spp, 1);  // batch 1: the plain split
        const run::SampleShare plain = run::share_of(r, ranks, spp);
        EXPECT_TRUE(one.first == plain.first && one.count == plain.count);
      }
      EXPECT_EQ(next, spp) << spp << " spp over " << ranks << " ranks: every sample once";
      const uint32_t batches = (spp + b - 1) / b;
      EXPECT_EQ(most, std::min(spp, (batches + ranks - 1) / ranks * b)) << spp << " spp, " << ranks << " ranks";
      EXPECT_EQ(run::share_of(0, ranks, spp, b).count, most) << "rank 0 traces whenever there is a batch";
    }
  EXPECT_EQ(run::share_of(1, 3, 800, b).first, 272u);  // 17 + 17 + 16 batches
  EXPECT_EQ(run::share_of(2, 3, 800, b).count, 256u);
  // Dynamic chunks end where a batch starts: every block of every chunk is then aligned.
  const uint32_t rows = 5;
  for (uint32_t spp : {1u, 15u, 16u, 17u, 40u, 800u}) {
    const uint64_t units = uint64_t(rows) * spp;
    uint64_t at = 0;
    for (uint64_t want = 1; at < units; want = want * 3 + 1) {  // chunks of growing, uneven sizes
      const uint64_t end = run::batch_start_at_or_after(at + want, spp, b, units);
      ASSERT_GT(end, at);
      for (uint64_t u = at + want; u < end; ++u) EXPECT_NE((u % spp) % b, 0u) << "a batch start was skipped";
      for (const run::FrameBlock& blk : run::blocks_of({at, end - at}, spp, rows))
        EXPECT_TRUE(aligned(blk.first_sample, spp) && aligned(blk.first_sample + blk.samples, spp))
            << spp << " spp: block of row " << blk.first_row << " samples " << blk.first_sample << " + " << blk.samples;
      at = end;
    }
    EXPECT_EQ(at, units);
    EXPECT_EQ(run::batch_start_at_or_after(units + 3, spp, b, units), units);
    EXPECT_EQ(run::batch_start_at_or_after(7, spp, 1, units), std::min<uint64_t>(7, units));  // batch 1: as asked
  }
}

TEST(RankSplit, BlocksOfAUnitRange) {
  using B = run::FrameBlock;
  // 12 rows x 11 spp: units 5..40 = row 0 samples 5..10, rows 1-2 whole, row 3 samples 0..6.
  EXPECT_EQ(run::blocks_of({5, 35}, 11, 12), (std::vector<B>{{0, 1, 5, 6}, {1, 2, 0, 11}, {3, 1, 0, 7}}));
  EXPECT_EQ(run::blocks_of({0, 132}, 11, 12), (std::vector<B>{{0, 12, 0, 11}}));
  EXPECT_EQ(run::blocks_of({13, 3}, 11, 12), (std::vector<B>{{1, 1, 2, 3}}));
  EXPECT_EQ(run::blocks_of({22, 11}, 11, 12), (std::vector<B>{{2, 1, 0, 11}}));
  EXPECT_TRUE(run::blocks_of({7, 0}, 11, 12).empty());
  EXPECT_THROW(run::blocks_of({130, 3}, 11, 12), std::invalid_argument);
  // Row ranges merge where they touch or overlap.
  std::vector<run::RowRange> rows;
  run::add_rows(rows, {5, 2, 0, 11});
  run::add_rows(rows, {0, 1, 3, 2});
  run::add_rows(rows, {7, 1, 0, 4});
  run::add_rows(rows, {6, 1, 0, 4});
  EXPECT_EQ(rows, (std::vector<run::RowRange>{{0, 1}, {5, 3}}));
  run::add_rows(rows, {1, 4, 0, 1});
  EXPECT_EQ(rows, (std::vector<run::RowRange>{{0, 8}}));
}

TEST(RankSplit, ChunksOfRowsGiveTheSameFilm) {
  // 12 rows x 11 spp = 132 units, cut across rows and inside them.
  expect_chunks_equal_whole(small(Strategy::Pixel, Isa::Auto), {0, 1, 12, 40, 41, 99, 132});
  expect_chunks_equal_whole(small(Strategy::Pixel, Isa::Scalar), {0, 66, 70, 132});
  expect_chunks_equal_whole(small(Strategy::Wavefront, Isa::Auto), {0, 5, 17, 23, 131, 132});
  expect_chunks_equal_whole(small(Strategy::Wavefront, Isa::Scalar), {0, 12, 132});
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
  // Samples [first, first + count) and rows likewise; count 0 = to the end of the frame.
  for (auto [first, count] : {std::pair<uint32_t, uint32_t>{10, 2}, {11, 0}}) {  // 11 spp
    RenderSettings s = small(Strategy::Pixel, Isa::Auto);
    s.first_sample = first, s.sample_count = count;
    EXPECT_THROW(s.validate(), std::invalid_argument);
  }
  for (auto [first, count] : {std::pair<uint32_t, uint32_t>{10, 3}, {12, 0}}) {  // 12 rows
    RenderSettings s = small(Strategy::Pixel, Isa::Auto);
    s.first_row = first, s.row_count = count;
    EXPECT_THROW(s.validate(), std::invalid_argument);
  }
}

TEST(RankSplit, ChunksFollowTheRateAndCoverTheFrame) {
  // Unmeasured: the probe.
  EXPECT_EQ(run::chunk_size(1024, 12, 0, 0), 12u);
  EXPECT_EQ(run::chunk_size(5, 12, 0, 0), 5u);
  // A rank with 3/4 of the total rate gets (3/4 + 0.2 x 3/4) x 3/4 of what is left.
  EXPECT_EQ(run::chunk_size(800, 12, 3.0, 4.0), 540u);
  // Never more than is left, never less than the probe.
  EXPECT_EQ(run::chunk_size(5, 12, 100.0, 100.0), 5u);
  EXPECT_EQ(run::chunk_size(500, 12, 1.0, 1000.0), 12u);
  EXPECT_EQ(run::chunk_size(500, 0, 1.0, 1000.0), 1u);
  EXPECT_EQ(run::chunk_size(0, 12, 1.0, 1.0), 0u);
  // Beyond 32 bits (a 65536-row frame at 2^17 spp), a rank of half the rate. (A rank of all
  // of it takes everything: ADominantRankTakesTheRest.)
  EXPECT_EQ(run::chunk_size(uint64_t(1) << 33, 12, 1.0, 2.0), uint64_t(0.425 * double(uint64_t(1) << 33)) + 1);
  // A GPU 30x a CPU, each asking when its chunk would end: the frame is covered exactly,
  // the GPU needs few chunks, and the CPU's work ends no later than the GPU's.
  const double rate[2] = {30.0, 1.0};
  double busy_until[2] = {0, 0};
  uint64_t next = 0, chunks[2] = {0, 0};
  while (next < 1024) {
    const int r = busy_until[0] <= busy_until[1] ? 0 : 1;
    const uint64_t c = run::chunk_size(1024 - next, 1, rate[r], 31.0);
    ASSERT_GT(c, 0u);
    next += c;
    busy_until[r] += double(c) / rate[r];
    ++chunks[r];
  }
  EXPECT_EQ(next, 1024u);
  EXPECT_LE(chunks[0], 6u);
  EXPECT_LE(busy_until[1], busy_until[0] * 1.05);
}

// Issue 30: a rank with >= 98 % of the total rate (a GPU beside a slow CPU rank) takes all
// that is left in one chunk, so the hybrid's GPU makes one more call at most, not a tail of
// shrinking chunks; just under the threshold the share rule still applies.
TEST(RankSplit, ADominantRankTakesTheRest) {
  EXPECT_EQ(run::chunk_size(204800, 8192, 99.0, 100.0), 204800u);
  EXPECT_EQ(run::chunk_size(204800, 8192, run::kDominantShare, 1.0), 204800u);
  EXPECT_LT(run::chunk_size(204800, 8192, 97.0, 100.0), 204800u);
}

// The bound under which the MPI and NCCL reductions add int64 sums unchecked (issue 30).
TEST(RankSplit, SumsCannotOverflowBound) {
  const uint64_t max = uint64_t(INT64_MAX);
  EXPECT_TRUE(run::sums_cannot_overflow({}));
  EXPECT_TRUE(run::sums_cannot_overflow({max}));
  EXPECT_TRUE(run::sums_cannot_overflow({max - 5, 5, 0}));
  EXPECT_FALSE(run::sums_cannot_overflow({max - 5, 6}));
  EXPECT_FALSE(run::sums_cannot_overflow({max, max, max, max}));  // no wrap in the bound's own sum
  EXPECT_FALSE(run::sums_cannot_overflow({uint64_t(1) << 63}));   // |INT64_MIN|
}

TEST(RankSplit, OneProcessIsOneRank) {
  run::World& w = run::World::get();
  EXPECT_EQ(w.size(), 1);
  EXPECT_TRUE(w.root());
  // Whole-frame dispensing in one rank: everything, then nothing.
  run::SampleDispenser d(w, 9);
  const run::UnitRange a = d.next(0, 2);
  EXPECT_EQ(a.first, 0u);
  EXPECT_EQ(a.count, 9u);
  EXPECT_EQ(d.next(1.0, 2).count, 0u);
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
  const std::vector<std::string> entries = {run::rank_entry(0, "a", s, r0, -1, 8 * 16 * 12, 1, 2.1).dump(),
                                            run::rank_entry(1, "b", s, r1, -1, 3 * 16 * 12, 2, 2.1).dump()};
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
  EXPECT_DOUBLE_EQ(x["per_rank"][1]["samples_per_pixel"].get<double>(), 3.0);
  EXPECT_EQ(x["per_rank"][1]["samples"], 3 * 16 * 12);
}

// A rank that left the barrier before rank 0 can trace longer than rank 0's frame (seen
// on a loaded 16-core host: efficiency 1.22); the efficiency is then measured against that
// rank's own wall time and stays <= 1.
TEST(RankSplit, EfficiencyNeverAboveOneWhenARankStartedEarly) {
  RenderSettings s = small(Strategy::Pixel, Isa::Auto);
  RunReport r0, r1;
  r0.paths = 100, r0.seconds = 0.010, r0.threads = 4;
  r1.paths = 100, r1.seconds = 0.016, r1.threads = 4;
  const std::vector<std::string> entries = {run::rank_entry(0, "a", s, r0, -1, 100, 1, 0.011).dump(),
                                            run::rank_entry(1, "a", s, r1, -1, 100, 1, 0.017).dump()};
  RunReport merged = r0;
  merged.settings = s;
  run::merge_ranks(merged, entries, 0.012, 0.001, "static");
  const double e = merged.extra["ranks"]["parallel_efficiency"].get<double>();
  EXPECT_DOUBLE_EQ(e, 0.026 / (2 * 0.017));
  EXPECT_LE(e, 1.0);
  EXPECT_DOUBLE_EQ(merged.seconds, 0.012);  // the frame itself is still rank 0's
}

}  // namespace
}  // namespace pb

// The overlapped reduction's bands (gpu_reduce.h, issue 30): one band below kBandSamples a
// rank (a band costs a tracer call: ~0.33 ms on an H100), then one per kBandSamples up to
// kMaxBands; PATHBENCH_REDUCE_BANDS fixes the count; never more bands than rows; the bands
// cover every row once, in order, as evenly as the rows go.
TEST(ReductionBands, CountFollowsTheRanksSamples) {
  using pb::run::reduction_bands;
  const uint64_t b = pb::run::kBandSamples;
  EXPECT_EQ(reduction_bands(256ull * 256 * 400, 256, 0), 1u);  // 256x256x800 over 2 ranks: one band
  EXPECT_EQ(reduction_bands(b - 1, 256, 0), 1u);
  EXPECT_EQ(reduction_bands(3 * b, 256, 0), 3u);
  EXPECT_EQ(reduction_bands(2048ull * 2048 * 512, 2048, 0), pb::run::kMaxBands);  // 2048x2048x1024 over 2
  EXPECT_EQ(reduction_bands(100 * b, 5, 0), 5u) << "at most one band a row";
  EXPECT_EQ(reduction_bands(0, 256, 4), 4u) << "asked for";
  EXPECT_EQ(reduction_bands(b * 100, 50, 64), 50u);
  EXPECT_EQ(reduction_bands(b * 100, 256, 1), 1u);
}

TEST(ReductionBands, BandsCoverEveryRowOnce) {
  for (uint32_t rows : {1u, 7u, 50u, 256u, 2048u})
    for (uint32_t bands = 1; bands <= std::min(rows, 64u); ++bands) {
      uint32_t next = 0, smallest = rows, largest = 0;
      for (uint32_t k = 0; k < bands; ++k) {
        const auto [first, count] = pb::run::band_rows(k, bands, rows);
        EXPECT_EQ(first, next) << rows << " rows, band " << k << " of " << bands;
        next = first + count;
        smallest = std::min(smallest, count);
        largest = std::max(largest, count);
      }
      EXPECT_EQ(next, rows);
      EXPECT_LE(largest - smallest, 1u);
      EXPECT_GE(smallest, 1u);
    }
}
