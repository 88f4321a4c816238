// GPU tracer tests (CTest label `gpu`). Without a usable CUDA device every test reports
// SKIPPED with the reason, and CTest counts it as passed.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <ostream>
#include <string>
#include <cstdio>
#include <cstdlib>

#include "pathbench/bvh/bvh_build.h"
#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/bvh/host_tracer.h"
#include "pathbench/bvh/sample_units.h"
#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/gpu/render.h"
#include "require_gpu.h"
#include "pathbench/run/run.h"
#include "film_agreement.h"
#include "refusal_check.h"
#include "traversal_check.h"
#if __has_include("../unit/stat_test.h")
#include "../unit/stat_test.h"
#define PB_HAVE_STAT_TEST 1
#endif

namespace pb::gpu {
using namespace pb::bvh;  // the BVH library (bvh/) the tracer under test uses
namespace {

RenderSettings small_settings(Strategy strategy, uint32_t size = 64, uint32_t spp = 32) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.max_bounces = 2;
  s.sampling = Sampling::Nee;
  s.strategy = strategy;
  s.device = Device::Gpu;
  s.seed = 1234;
  s.progress = false;
  return s;
}

Film render_gpu(const Scene& scene, const GpuScene& gs, RenderSettings s, RunReport* out = nullptr) {
  Film film(s.width, s.height, s.variance);
  RunReport r;
  film.begin(s.spp, scene.max_emission());  // as the run layer does before it calls the tracer
  render(scene, gs, s, film, r, false);
  EXPECT_EQ(r.paths, s.total_samples());
  EXPECT_EQ(r.discarded_samples, 0u);
  if (out) *out = r;
  return film;
}

void expect_identical(const Film& a, const Film& b, const char* what) {
  ASSERT_EQ(a.raw_sums().size(), b.raw_sums().size());
  size_t differ = 0;
  for (size_t i = 0; i < a.raw_sums().size(); ++i) differ += a.raw_sums()[i] != b.raw_sums()[i];
  EXPECT_EQ(differ, 0u) << what << ": film sums differ in " << differ << " values";
  EXPECT_EQ(a.counts(), b.counts()) << what;
}

struct StrategyCase {
  const char* scene;
  Sampling sampling;
  int bounces;  // -1: unbounded with Russian roulette
};

void PrintTo(const StrategyCase& c, std::ostream* os) {
  *os << c.scene << " " << to_string(c.sampling) << " " << c.bounces;
}

class GpuStrategies : public ::testing::TestWithParam<StrategyCase> {};

// pixel, wavefront (small pool: many refills) and paper-queue: bit-identical films.
TEST_P(GpuStrategies, BitIdenticalFilms) {
  PB_REQUIRE_GPU();
  Scene scene;
  try {
    scene = load_scene(GetParam().scene);
  } catch (const InputError& e) {
    GTEST_SKIP() << "scene " << GetParam().scene << " not available: " << e.what();
  }
  const GpuScene gs(scene);
  RenderSettings s = small_settings(Strategy::Pixel, 48, 24);
  s.sampling = GetParam().sampling;
  s.max_bounces = GetParam().bounces;
  s.russian_roulette = s.max_bounces < 0;
  const Film pixel = render_gpu(scene, gs, s);
  s.strategy = Strategy::Wavefront;
  s.paths_in_flight = 3001;  // odd size, many refills
  RunReport wr;
  const Film wave = render_gpu(scene, gs, s, &wr);
  EXPECT_GT(wr.state_bytes_per_path, 0u);
  expect_identical(pixel, wave, "pixel vs wavefront");
  s.paths_in_flight = 0;  // device default
  expect_identical(pixel, render_gpu(scene, gs, s), "pixel vs wavefront (default pool)");
  s.strategy = Strategy::PaperQueue;
  expect_identical(pixel, render_gpu(scene, gs, s), "pixel vs paper-queue");
}

INSTANTIATE_TEST_SUITE_P(Cases, GpuStrategies,
                         ::testing::Values(StrategyCase{"paper-cornell", Sampling::Nee, 2},
                                           StrategyCase{"paper-cornell", Sampling::Uniform, 2},
                                           StrategyCase{"paper-cornell", Sampling::Cosine, -1},
                                           StrategyCase{"cornell-box", Sampling::Nee, -1},
                                           StrategyCase{"paper-cornell-ico:3", Sampling::Nee, 3},
                                           // Materials beyond Lambertian (the shade kernel's other instantiation).
                                           StrategyCase{"cornell-box:spheres", Sampling::Nee, -1},
                                           StrategyCase{"cornell-box:ggx", Sampling::Nee, 4},
                                           StrategyCase{"cornell-box:mirror", Sampling::Cosine, 3}),
                         [](const auto& info) {
                           std::string n = std::string(info.param.scene) + "_" + to_string(info.param.sampling) + "_" +
                                           (info.param.bounces < 0 ? std::string("rr") : std::to_string(info.param.bounces));
                           for (char& ch : n)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return n;
                         });

// A frame with many more chunks of 32 samples than the device has warps: the megakernel
// takes them all from its counter, the wavefront's stages their last rounds
// (work_chunks.cuh); the tests above, whose frames are smaller than one round, take theirs
// by grid stride. Every sample still rendered once: films bit-identical, paths = samples.
TEST(GpuWorkChunks, BitIdenticalWhenWorkComesFromTheCounters) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  const GpuScene gs(scene);
  RenderSettings s = small_settings(Strategy::Pixel, 128, 64);  // 1 M samples, 32,768 chunks
  const Film pixel = render_gpu(scene, gs, s);
  s.strategy = Strategy::Wavefront;
  expect_identical(pixel, render_gpu(scene, gs, s), "pixel vs wavefront (default pool)");
  s.paths_in_flight = 100003;  // ~3,100 chunks an iteration: a round or two of any stage
  expect_identical(pixel, render_gpu(scene, gs, s), "pixel vs wavefront (pool of 100,003)");
}

// The wavefront's samples split among 1 to 4 pools on streams of their own (run_pools,
// PATHBENCH_GPU_WAVEFRONT_POOLS), with pools of uneven size: every sample rendered once,
// films bit-identical to the megakernel's; the report names the pool count. A count the
// variable cannot mean is an InputError naming it.
TEST(GpuWavefrontPools, BitIdenticalForAnyPoolCount) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  const GpuScene gs(scene);
  RenderSettings s = small_settings(Strategy::Pixel, 96, 32);
  const Film pixel = render_gpu(scene, gs, s);
  s.strategy = Strategy::Wavefront;
  for (const char* pools : {"1", "2", "3", "4"})
    for (uint64_t pif : {uint64_t(0), uint64_t(10007)}) {  // 0: the default pool
      ::setenv("PATHBENCH_GPU_WAVEFRONT_POOLS", pools, 1);
      s.paths_in_flight = pif;
      RunReport r;
      const std::string what = std::string("pools ") + pools + ", paths in flight " + std::to_string(pif);
      expect_identical(pixel, render_gpu(scene, gs, s, &r), what.c_str());
      EXPECT_EQ(r.extra["pools"], std::stoi(pools)) << what;
    }
  ::setenv("PATHBENCH_GPU_WAVEFRONT_POOLS", "5", 1);
  ::pb::test::expect_refused_naming(scene, gs, s, "PATHBENCH_GPU_WAVEFRONT_POOLS");
  ::unsetenv("PATHBENCH_GPU_WAVEFRONT_POOLS");
}

// The megakernel's path state parked in shared memory (PATHBENCH_GPU_PIXEL_PARKED; auto: the
// leaves layout) or kept in registers: the same arithmetic, so the same film bit for bit, on
// the leaves layout (paper-cornell) and on the binary BVH at 5, 6 and 8 blocks (ico:3, binary by
// name); the report says which ran. A value the variable cannot mean is an InputError naming it.
TEST(GpuPixelParked, SameFilmAsInRegisters) {
  PB_REQUIRE_GPU();
  auto parked_of = [](const RunReport& r) { return r.extra["pixel_occupancy"]["parked_path_state"].get<bool>(); };
  const RenderSettings s = small_settings(Strategy::Pixel, 64, 64);
  {
    const Scene scene = load_scene("paper-cornell");
    const GpuScene gs(scene);
    RunReport r;
    const Film parked = render_gpu(scene, gs, s, &r);  // auto: parked, at kLeavesParkedBlocks
    EXPECT_TRUE(parked_of(r));
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "0", 1);
    expect_identical(parked, render_gpu(scene, gs, s, &r), "leaves: parked vs in registers");
    EXPECT_FALSE(parked_of(r));
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "1", 1);
    ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", "3", 1);
    expect_identical(parked, render_gpu(scene, gs, s, &r), "leaves: parked at 3 blocks");
    EXPECT_TRUE(parked_of(r));
  }
  {
    const Scene scene = load_scene("paper-cornell-ico:3");
    GpuBvhOptions o;
    o.layout = GpuBvhLayout::Binary;
    const GpuScene gs(scene, o);
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "0", 1);
    ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
    const Film in_registers = render_gpu(scene, gs, s);
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "1", 1);
    for (const char* blocks : {"5", "6", "8"}) {
      ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", blocks, 1);
      RunReport r;
      const std::string what = std::string("binary: parked at ") + blocks + " blocks";
      expect_identical(in_registers, render_gpu(scene, gs, s, &r), what.c_str());
      EXPECT_TRUE(parked_of(r)) << what;
      EXPECT_EQ(r.extra["pixel_occupancy"]["min_blocks_per_sm"], std::stoi(blocks)) << what;
    }
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "yes", 1);
    ::pb::test::expect_refused_naming(scene, gs, s, "PATHBENCH_GPU_PIXEL_PARKED");
  }
  ::unsetenv("PATHBENCH_GPU_PIXEL_PARKED");
  ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
}

// auto's occupancy for the binary BVH from kPixelLatencyBoundTris triangles on: 8 blocks with the
// path state in registers while the BVH fits the device's L2 (ico:5, ~2 MB), kPixelBigBvhBlocks
// with it parked beyond (ico:8, ~111 MB: more than any current GPU's L2); the report names
// the sizes compared, and the film is the one 8 blocks in registers give.
TEST(GpuPixelOccupancy, BigBinaryBvhParkedAtSixBlocks) {
  PB_REQUIRE_GPU();
  ::unsetenv("PATHBENCH_GPU_PIXEL_PARKED");
  ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  const RenderSettings s = small_settings(Strategy::Pixel, 32, 32);
  for (const char* name : {"paper-cornell-ico:5", "paper-cornell-ico:8"}) {
    const Scene scene = load_scene(name);
    const GpuScene gs(scene);
    RunReport r;
    const Film film = render_gpu(scene, gs, s, &r);
    const auto& occ = r.extra["pixel_occupancy"];
    const bool big = r.extra["bvh"]["device_bytes"].get<uint64_t>() > r.extra["gpu"]["l2_bytes"].get<uint64_t>();
    EXPECT_EQ(r.extra["bvh"]["layout"], "binary") << name;
    EXPECT_EQ(big, std::string(name) == "paper-cornell-ico:8") << name << ": " << r.extra["bvh"]["device_bytes"];
    EXPECT_EQ(occ["min_blocks_per_sm"], big ? 6 : 8) << name << ": " << occ["why"];
    EXPECT_EQ(occ["parked_path_state"], big) << name << ": " << occ["why"];
    ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", "8", 1);
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "0", 1);
    expect_identical(film, render_gpu(scene, gs, s, &r), name);
    EXPECT_EQ(r.extra["pixel_occupancy"]["min_blocks_per_sm"], 8) << name;
    ::unsetenv("PATHBENCH_GPU_PIXEL_PARKED");
    ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  }
}

// auto's occupancy by path length on the binary BVH (strategies.cuh: kLongPathBlocks 5, from
// kLongPathBounces 3 bounces below kPixelLatencyBoundTris triangles, else 8 from kPixelTinyTris 64
// triangles and 3 below; from kLongPathLatencyBounces 8 above, else 8), unbounded paths counted
// long; a BVH beyond the L2 keeps kPixelBigBvhBlocks (6). The block count never changes the film.
TEST(GpuPixelOccupancy, ByPathLength) {
  PB_REQUIRE_GPU();
  ::unsetenv("PATHBENCH_GPU_PIXEL_PARKED");
  ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  struct Case {
    const char* scene;
    int32_t bounces;
    int blocks;
  };
  for (const Case& k : {Case{"cornell-box", 2, 3}, Case{"cornell-box", 3, 5}, Case{"cornell-box", -1, 5},
                        Case{"paper-cornell-ico:2", 2, 8}, Case{"paper-cornell-ico:2", 3, 5},
                        Case{"paper-cornell-ico:5", 7, 8}, Case{"paper-cornell-ico:5", 8, 5},
                        Case{"paper-cornell-ico:8", 8, 6}}) {
    const Scene scene = load_scene(k.scene);
    const GpuScene gs(scene);
    RenderSettings s = small_settings(Strategy::Pixel, 16, 16);
    s.max_bounces = k.bounces;
    s.russian_roulette = k.bounces < 0;
    const std::string what = std::string(k.scene) + " at " + std::to_string(k.bounces) + " bounces";
    RunReport r;
    const Film film = render_gpu(scene, gs, s, &r);
    EXPECT_EQ(r.extra["bvh"]["layout"], "binary") << what;
    EXPECT_EQ(r.extra["pixel_occupancy"]["min_blocks_per_sm"], k.blocks) << what << ": " << r.extra["pixel_occupancy"]["why"];
    ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", "3", 1);
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "0", 1);
    expect_identical(film, render_gpu(scene, gs, s), what.c_str());
    ::unsetenv("PATHBENCH_GPU_PIXEL_PARKED");
    ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  }
}

// The binary and wide BVHs' latency-bound megakernels (more than 3 blocks) trace a pixel's
// samples in units of up to 256 grouped by their first bounce (sample_order.cuh) from
// kOrderMinSpp samples a pixel on; at 3 blocks, and below that spp, chunks of 32 in sample order.
// Only which samples share a warp changes and the film sums integers: the same film bit for bit
// (300 spp: units of 256 and of 44), parked or not, and the report says which order ran.
TEST(GpuPixelLaneOrder, SameFilmAsSampleOrder) {
  PB_REQUIRE_GPU();
  auto ordered_of = [](const RunReport& r) { return r.extra["pixel_occupancy"]["lanes_ordered_by_first_bounce"].get<bool>(); };
  const Scene scene = load_scene("paper-cornell-ico:3");
  RenderSettings s = small_settings(Strategy::Pixel, 12, 300);
  s.variance = true;
  for (const GpuBvhLayout layout : {GpuBvhLayout::Binary, GpuBvhLayout::Wide8}) {
    GpuBvhOptions o;
    o.layout = layout;
    const GpuScene gs(scene, o);
    const std::string name = to_string(layout);
    ::setenv("PATHBENCH_GPU_PIXEL_PARKED", "0", 1);
    ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", "3", 1);
    RunReport r;
    const Film in_order = render_gpu(scene, gs, s, &r);
    EXPECT_FALSE(ordered_of(r)) << name << " at 3 blocks";
    const bool binary = layout == GpuBvhLayout::Binary;
    for (const char* blocks : {"5", "6", "8"}) {
      if (!binary && std::string(blocks) == "6") continue;  // compiled for the binary BVH only
      for (const char* parked : {"0", "1"}) {
        if (!binary && std::string(parked) == "1") continue;
        ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", blocks, 1);
        ::setenv("PATHBENCH_GPU_PIXEL_PARKED", parked, 1);
        const std::string what = name + " at " + blocks + " blocks, parked " + parked;
        expect_identical(in_order, render_gpu(scene, gs, s, &r), what.c_str());
        EXPECT_TRUE(ordered_of(r)) << what;
        EXPECT_EQ(r.extra["pixel_occupancy"]["min_blocks_per_sm"], std::stoi(blocks)) << what;
      }
    }
  }
  RenderSettings few = s;
  few.spp = bvh::kOrderMinSpp - 1;
  const GpuScene gs(scene);
  ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", "8", 1);
  RunReport r;
  render_gpu(scene, gs, few, &r);
  EXPECT_FALSE(ordered_of(r)) << few.spp << " spp: chunks of 32 in sample order";
  ::unsetenv("PATHBENCH_GPU_PIXEL_PARKED");
  ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
}

// GPU against the CPU tracer, same seed and settings: with one random stream the
// images differ only where rounding sends a path to another triangle.
void gpu_vs_cpu(const char* name) {
  Scene scene;
  try {
    scene = load_scene(name);
  } catch (const InputError& e) {
    GTEST_SKIP() << "scene " << name << " not available: " << e.what();
  }
  RenderSettings s = small_settings(Strategy::Pixel, 64, 64);
  s.variance = true;
  Film gpu_film(s.width, s.height, true), cpu_film(s.width, s.height, true);
  RunReport gr, cr;
  run::render(scene, s, gpu_film, gr);
  RenderSettings sc = s;
  sc.device = Device::Cpu;
  run::render(scene, sc, cpu_film, cr);
  const ::pb::test::FilmAgreement a = ::pb::test::film_agreement(gpu_film, cpu_film);
  const double share = a.share_within();
  std::printf("[ INFO     ] %s GPU vs CPU, %ux%u, %u spp: %.4f%% of pixels within 1e-4 relative; %.4f%% of pixels differ "
              "at all (film sums); largest relative difference %.3g\n",
              name, s.width, s.height, s.spp, 100.0 * share, 100.0 * double(a.differ) / double(a.pixels), a.worst);
  ::testing::Test::RecordProperty("share_within_1e-4", std::to_string(share));
  ::testing::Test::RecordProperty("share_differing", std::to_string(double(a.differ) / double(a.pixels)));
  EXPECT_GE(share, 0.99);
  EXPECT_EQ(gr.paths, cr.paths);
#if PB_HAVE_STAT_TEST
  const auto g = gpu_film.mean(), c = cpu_film.mean();
  const auto t = stat::compare_images(g, gpu_film.variance_of_mean(), c, cpu_film.variance_of_mean());
  std::printf("[ INFO     ] %s statistical test: %s\n", name, t.summary().c_str());
  EXPECT_EQ(t.passed, t.values) << t.summary();
#endif
}

// The GPU's samples computed on the CPU (host_tracer.h: what a CPU rank beside GPU
// ranks traces) give the GPU's film byte for byte: the hybrid render's premise.
void host_tracer_vs_gpu(const char* name, Sampling sampling, int bounces, Precision precision = Precision::Float) {
  const Scene scene = load_scene(name);
  RenderSettings s = small_settings(Strategy::Pixel, 48, 24);
  s.sampling = sampling;
  s.max_bounces = bounces;
  s.precision = precision;
  const GpuScene gs(scene);
  const Film gpu_film = render_gpu(scene, gs, s);
  Film host_film(s.width, s.height, false);
  host_film.begin(s.spp, scene.max_emission());
  RunReport r;
  HostGpuTracer(scene).render(s, host_film, r);
  EXPECT_EQ(r.paths, s.total_samples());
  expect_identical(gpu_film, host_film, name);
  EXPECT_EQ(gpu_film.counts(), host_film.counts());
}

TEST(HostGpuTracer, SameFilmAsTheGpu) {
  PB_REQUIRE_GPU();
  host_tracer_vs_gpu("paper-cornell", Sampling::Nee, 2);
  host_tracer_vs_gpu("paper-cornell", Sampling::Uniform, 2);
  host_tracer_vs_gpu("cornell-box", Sampling::Nee, -1);
  host_tracer_vs_gpu("cornell-box:ggx", Sampling::Nee, 4);
  host_tracer_vs_gpu("cornell-box:glass", Sampling::Cosine, 3);
  host_tracer_vs_gpu("paper-cornell-ico:3", Sampling::Nee, 3);
  host_tracer_vs_gpu("paper-cornell", Sampling::Nee, 2, Precision::Double);
}

// An MPI rank's chunks (run/rank_tracer.cpp): blocks of rows x samples added into one
// film kept on the device, downloaded once, give the whole render's film byte for byte.
TEST(DeviceFilm, BlocksAddUpToTheWholeFrame) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  const GpuScene gpu_scene(scene);
  for (Strategy strategy : {Strategy::Pixel, Strategy::Wavefront, Strategy::PaperQueue}) {
    const RenderSettings s = small_settings(strategy, 48, 16);
    Film whole(s.width, s.height, false);
    whole.begin(s.spp, scene.max_emission());
    RunReport wr;
    render(scene, gpu_scene, s, whole, wr);
    Film kept(s.width, s.height, false);
    kept.begin(s.spp, scene.max_emission());
    DeviceFilm device_film;
    EXPECT_FALSE(device_film.used());
    uint64_t paths = 0;
    // {first_row, rows, first_sample, samples}: all rows' first samples, then bands.
    const uint32_t blocks[][4] = {{0, 48, 0, 3}, {0, 10, 3, 13}, {10, 1, 3, 7}, {10, 1, 10, 6}, {11, 37, 3, 13}};
    for (const auto& b : blocks) {
      RenderSettings c = s;
      c.first_row = b[0], c.row_count = b[1], c.first_sample = b[2], c.sample_count = b[3];
      RunReport r;
      render(scene, gpu_scene, c, kept, r, false, &device_film);
      paths += r.paths;
    }
    EXPECT_EQ(kept.counts(), std::vector<uint32_t>(kept.counts().size(), 0u)) << "the host film is left alone";
    EXPECT_GE(device_film.download(kept), 0.0);
    EXPECT_EQ(paths, wr.paths);
    expect_identical(whole, kept, to_string(strategy));
    EXPECT_EQ(whole.counts(), kept.counts());
  }
}

// gpu::render keeps its per-call setup for the process's next render (render_cache.cuh's
// RenderCache, issue 30): equal chunks of a kept film reuse the kept wavefront pools,
// renders of other strategies in between release them, and every film stays the one
// render's byte for byte (and the report's pool count the pools that ran).
TEST(DeviceFilm, KeptSetupAcrossRendersGivesTheSameFilms) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  const GpuScene gpu_scene(scene);
  for (Strategy strategy : {Strategy::Wavefront, Strategy::Pixel}) {
    const RenderSettings s = small_settings(strategy, 48, 16);
    const Film whole = render_gpu(scene, gpu_scene, s);
    for (int round = 0; round < 2; ++round) {
      Film kept(s.width, s.height, false);
      kept.begin(s.spp, scene.max_emission());
      DeviceFilm device_film;
      // Four equal blocks (24 rows x 8 samples): the same pools each time; a render of the
      // other strategy between the second and third releases them.
      const uint32_t blocks[][4] = {{0, 24, 0, 8}, {24, 24, 0, 8}, {0, 24, 8, 8}, {24, 24, 8, 8}};
      int k = 0;
      for (const auto& b : blocks) {
        if (k++ == 2) {
          RenderSettings other = small_settings(strategy == Strategy::Pixel ? Strategy::Wavefront : Strategy::Pixel, 16, 4);
          (void)render_gpu(scene, gpu_scene, other);
        }
        RenderSettings c = s;
        c.first_row = b[0], c.row_count = b[1], c.first_sample = b[2], c.sample_count = b[3];
        RunReport r;
        render(scene, gpu_scene, c, kept, r, false, &device_film);
        if (strategy == Strategy::Wavefront) EXPECT_GE(r.extra.value("pools", 0), 1);
      }
      device_film.download(kept);
      expect_identical(whole, kept, to_string(strategy));
      EXPECT_EQ(whole.counts(), kept.counts());
    }
  }
}

// What run/'s NCCL reduction reads of a device film (issue 30): its arrays on the device,
// and the largest |sum|, the same as the downloaded film's.
TEST(DeviceFilm, ArraysAndLargestSum) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  const GpuScene gpu_scene(scene);
  const RenderSettings s = small_settings(Strategy::Pixel, 40, 8);
  Film film(s.width, s.height, false);
  film.begin(s.spp, scene.max_emission());
  DeviceFilm device_film;
  EXPECT_THROW(device_film.arrays(), std::logic_error);
  RunReport r;
  render(scene, gpu_scene, s, film, r, false, &device_film);
  const DeviceFilm::Arrays a = device_film.arrays();
  EXPECT_EQ(a.pixels, uint64_t(s.width) * s.height);
  EXPECT_NE(a.sums, nullptr);
  EXPECT_NE(a.counts, nullptr);
  EXPECT_EQ(a.sum_sq, nullptr);
  device_film.download(film);
  uint64_t largest = 0;
  for (int64_t v : film.raw_sums()) largest = std::max<uint64_t>(largest, v < 0 ? uint64_t(0) - uint64_t(v) : uint64_t(v));
  EXPECT_GT(largest, 0u);
  EXPECT_EQ(device_film.max_abs_sum(), largest);
}

TEST(GpuVsCpu, PaperCornell) {
  PB_REQUIRE_GPU();
  gpu_vs_cpu("paper-cornell");
}
// Issue 15's frame: paper-cornell 256x256x800, 2 bounces, nee, seed 0, the pixel strategy
// on both devices: >= 99.99 % of the pixels within 1e-4 (the CPU-only twin is
// HostGpuTracerSlow.PaperFrameWithinAcceptance, test_host_tracer.cpp).
TEST(GpuVsCpu, PaperFrameWithinAcceptance) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  RenderSettings s = small_settings(Strategy::Pixel, 256, 800);
  s.seed = 0;
  Film gpu_film(s.width, s.height, false), cpu_film(s.width, s.height, false);
  RunReport gr, cr;
  run::render(scene, s, gpu_film, gr);
  s.device = Device::Cpu;
  run::render(scene, s, cpu_film, cr);
  const ::pb::test::FilmAgreement a = ::pb::test::film_agreement(gpu_film, cpu_film);
  std::printf("[ INFO     ] paper-cornell 256x256x800 GPU vs CPU: %.4f%% of pixels within 1e-4 (%zu of %zu), %zu differ\n",
              100.0 * a.share_within(), a.within, a.pixels, a.differ);
  EXPECT_GE(a.share_within(), 0.9999);
  EXPECT_EQ(gr.paths, cr.paths);
}
TEST(GpuVsCpu, CornellBox) {
  PB_REQUIRE_GPU();
  gpu_vs_cpu("cornell-box");
}
TEST(GpuVsCpu, CornellBoxSpheres) {  // mirror + glass
  PB_REQUIRE_GPU();
  gpu_vs_cpu("cornell-box:spheres");
}
TEST(GpuVsCpu, CornellBoxGgx) {  // rough conductor
  PB_REQUIRE_GPU();
  gpu_vs_cpu("cornell-box:ggx");
}

// The traversal cross-check of tests/gpu/test_traversal.cpp, run on the device in
// every BVH layout: the device traversal returns what the host traversal of the same
// layout returns, and agrees with Embree.
TEST(GpuTraversal, DeviceMatchesHostAndEmbree) {
  PB_REQUIRE_GPU();
  for (const char* name : {"paper-cornell", "paper-cornell-ico:3"})
  for (GpuBvhLayout layout :
       {GpuBvhLayout::Binary, GpuBvhLayout::Wide4, GpuBvhLayout::Wide8, GpuBvhLayout::Brute, GpuBvhLayout::Leaves,
        GpuBvhLayout::Rects, GpuBvhLayout::RectsBinary}) {
    if (layout == GpuBvhLayout::Rects && std::string(name) != "paper-cornell") continue;  // rectangles only
    if (layout == GpuBvhLayout::RectsBinary && std::string(name) == "paper-cornell") continue;  // and a mesh
    Scene scene;
    try {
      scene = load_scene(name);
    } catch (const InputError&) {
      continue;
    }
    GpuBvhOptions options;
    options.layout = layout;
    const SceneBvhHost bvh = build_scene_bvh(scene, options);
    const Vec3f ext = scene.bounds_max - scene.bounds_min;
    const Vec3f lo = scene.bounds_min + ext * 0.02f, hi = scene.bounds_max - ext * 0.02f;
    auto rays = bvh::test::random_rays(lo, hi, 20000, 9);
    const auto edge = bvh::test::edge_and_vertex_rays(scene, lo, hi, 8, 13);
    rays.insert(rays.end(), edge.begin(), edge.end());
    std::vector<TraceQuery> q(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) q[i] = {rays[i].o, rays[i].d, rays[i].t_max};
    const auto dev = trace_on_device(scene, q, false, options);
    const bvh::test::EmbreeReference ref(scene);
    bvh::test::Agreement with_host, with_embree;
    with_embree.edge_rays = true;  // random rays plus rays aimed at edges (see test_traversal.cpp)
    size_t misses = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      bvh::test::Hit h;
      h.prim = traverse<false>(bvh.view(), rays[i].o, rays[i].d, rays[i].t_max, h.t);
      const bvh::test::Hit d{dev[i].prim, dev[i].t};
      with_host.add(rays[i], d, h);  // same code on both sides: no tolerance for edges needed
      misses += d.prim == kNoHit;
      const bvh::test::Hit e = ref.closest(rays[i]);
      if (e.prim != kNoHit) with_embree.add(rays[i], d, e, bvh::test::hit_cos(scene, rays[i], d));
    }
    std::printf("[ INFO     ] %s %s device traversal: %zu rays; vs host: %zu hit/miss, %zu prim (%zu not ties), %zu t; "
                "vs Embree: %zu hit/miss, %zu prim (%zu not ties), %zu t; %zu misses\n",
                name, to_string(layout), rays.size(), with_host.hit_miss_mismatch, with_host.prim_mismatch, with_host.prim_mismatch_not_tie,
                with_host.t_mismatch, with_embree.hit_miss_mismatch, with_embree.prim_mismatch,
                with_embree.prim_mismatch_not_tie, with_embree.t_mismatch, misses);
    EXPECT_EQ(misses, 0u) << name << ": closed scene, every ray must hit";
    EXPECT_EQ(with_host.hit_miss_mismatch, 0u) << with_host.first_problem;
    EXPECT_EQ(with_host.prim_mismatch_not_tie, 0u) << with_host.first_problem;
    EXPECT_EQ(with_host.t_mismatch, 0u) << with_host.first_problem;
    EXPECT_EQ(with_embree.prim_mismatch_not_tie, 0u) << with_embree.first_problem;
    EXPECT_EQ(with_embree.t_mismatch, 0u) << with_embree.first_problem;
  }
}

// The paper's global queue refuses, clearly, when the frame does not fit.
TEST(PaperQueue, RefusesWhenTheQueueDoesNotFit) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  RenderSettings s = small_settings(Strategy::PaperQueue, 2048, 1024);
  Film film(s.width, s.height, false);
  RunReport r;
  try {
    run::render(scene, s, film, r);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    std::printf("[ INFO     ] refusal: %s\n", msg.c_str());
    EXPECT_NE(msg.find("--spp"), std::string::npos) << msg;
    EXPECT_NE(msg.find("paper-queue"), std::string::npos) << msg;
  }
}

// The wavefront's default pool at the largest frame issue 15 names (2048 x 2048; 1 spp is
// already 4 M samples, more than the pool holds): pool, film and scene within
// kWavefrontBudgetBytes, and the device's peak, driver overhead included, within 512 MB;
// at 256 x 256 the smaller film leaves the pool more. kWavefrontPools pools.
TEST(GpuWavefrontPools, DefaultPoolStaysWithinTheBudget) {
  PB_REQUIRE_GPU();
  ::unsetenv("PATHBENCH_GPU_WAVEFRONT_POOLS");
  const Scene scene = load_scene("paper-cornell");
  const GpuScene gs(scene);
  uint64_t paths_2048 = 0;
  for (uint32_t size : {2048u, 256u}) {
    RenderSettings s = small_settings(Strategy::Wavefront, size, size == 2048 ? 1 : 64);
    RunReport r;
    render_gpu(scene, gs, s, &r);
    const uint64_t pool = r.extra["pool_device_bytes"], film = r.extra["film_device_bytes"];
    const uint64_t scene_bytes = r.extra["scene_device_bytes"];
    std::printf("[ INFO     ] %ux%u wavefront: %llu paths in flight, pool %.1f MB + film %.1f MB + scene %.3f MB; "
                "peak %.1f MB\n", size, size, static_cast<unsigned long long>(r.paths_in_flight), pool / 1e6,
                film / 1e6, scene_bytes / 1e6, r.peak_device_bytes / 1e6);
    EXPECT_EQ(r.extra["pools"], kWavefrontPools);
    EXPECT_LE(pool + film + scene_bytes, kWavefrontBudgetBytes + 4096) << size;  // + the pools' counters
    EXPECT_LE(r.peak_device_bytes, uint64_t(512) << 20) << size;
    if (size == 2048) paths_2048 = r.paths_in_flight;
    else EXPECT_GT(r.paths_in_flight, paths_2048);
  }
}

TEST(GpuReport, HasDeviceFacts) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell");
  RenderSettings s = small_settings(Strategy::Wavefront, 32, 8);
  Film film(s.width, s.height, false);
  RunReport r;
  run::render(scene, s, film, r, {.profile = true});
  const auto j = r.to_json();
  EXPECT_GT(j["device_seconds"].get<double>(), 0.0);
  EXPECT_GT(j["peak_device_bytes"].get<uint64_t>(), 0u);
  EXPECT_GT(j["state_bytes_per_path"].get<uint64_t>(), 0u);
  EXPECT_FALSE(j["gpu"]["name"].get<std::string>().empty());
  EXPECT_TRUE(j.contains("profile"));
  EXPECT_GT(r.rays.shadow, 0u);
  EXPECT_EQ(r.rays.camera, s.total_samples());
}

}  // namespace
}  // namespace pb::gpu
