// The GPU tracer's samples on the CPU (gpu/host_tracer.h), without a GPU: its film is
// exact under any split of the samples and any thread count (what MPI chunks need), and
// it renders what the CPU tracer renders (the same pixels within 1e-4, as the GPU does:
// tests/gpu/test_gpu.cpp's GpuVsCpu). That it equals the GPU's film byte for byte is
// HostGpuTracer.SameFilmAsTheGpu in test_gpu.cpp (label gpu).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "film_agreement.h"
#include "pathbench/bvh/host_tracer.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/cpu/embree_facts.h"
#include "pathbench/run/ranks.h"
#include "pathbench/run/run.h"

namespace pb::bvh {
namespace {

RenderSettings settings(uint32_t size, uint32_t spp) {
  RenderSettings s;
  s.width = s.height = size;
  s.spp = spp;
  s.max_bounces = 2;
  s.sampling = Sampling::Nee;
  s.device = Device::Cpu;
  s.seed = 99;
  s.progress = false;
  return s;
}

// Blocks {first_row, rows (0: to the end), first_sample, samples} traced into one film.
Film host_film(const Scene& scene, const HostGpuTracer& t, const RenderSettings& s,
               std::initializer_list<run::FrameBlock> blocks, RunReport& r) {
  Film f(s.width, s.height, false);
  f.begin(s.spp, scene.max_emission());
  for (const run::FrameBlock& b : blocks) {
    RenderSettings c = s;
    c.first_row = b.first_row;
    c.row_count = b.rows;
    c.first_sample = b.first_sample;
    c.sample_count = b.samples;
    t.render(c, f, r);
  }
  return f;
}

TEST(HostGpuTracer, ExactUnderAnySplitOfSamplesAndThreads) {
  const Scene scene = load_scene("paper-cornell");
  const HostGpuTracer tracer(scene);
  RenderSettings s = settings(24, 16);
  RunReport whole_r, split_r, one_r;
  const Film whole = host_film(scene, tracer, s, {{0, 0, 0, 16}}, whole_r);
  // Sample ranges of every row, and blocks of rows (a dynamic chunk's: run/ranks.h).
  const Film split = host_film(scene, tracer, s, {{0, 0, 0, 5}, {0, 0, 5, 1}, {0, 7, 6, 10}, {7, 1, 6, 3},
                                                  {7, 1, 9, 7}, {8, 0, 6, 10}}, split_r);
  s.threads = 1;
  const Film one_thread = host_film(scene, tracer, s, {{0, 0, 0, 16}}, one_r);
  EXPECT_EQ(whole.raw_sums(), split.raw_sums());
  EXPECT_EQ(whole.counts(), split.counts());
  EXPECT_EQ(whole.raw_sums(), one_thread.raw_sums());
  EXPECT_EQ(whole_r.paths, uint64_t(24) * 24 * 16);
  EXPECT_EQ(split_r.paths, whole_r.paths);
  EXPECT_EQ(split_r.rays.total(), whole_r.rays.total());
  EXPECT_GT(whole_r.rays.shadow, 0u);
}

TEST(HostGpuTracer, RendersWhatTheCpuTracerRenders) {
  for (const char* name : {"paper-cornell", "cornell-box:ggx"}) {
    const Scene scene = load_scene(name);
    const RenderSettings s = settings(32, 16);
    RunReport hr, cr;
    const Film host = host_film(scene, HostGpuTracer(scene), s, {{0, 0, 0, 16}}, hr);
    Film cpu(s.width, s.height, false);
    run::render(scene, s, cpu, cr);
    EXPECT_GE(test::film_agreement(host, cpu).share_within(), 0.99) << name;
    EXPECT_EQ(hr.paths, cr.paths) << name;
  }
}

// Issue 15's frame: paper-cornell 256x256x800, 2 bounces, nee, seed 0. The GPU's samples
// (computed here; HostGpuTracer.SameFilmAsTheGpu holds them to the GPU's film byte for byte)
// against the CPU tracer's: >= 99.99 % of the pixels within 1e-4. What parts them is a few
// single samples whose rays meet a box corner line or the light's edge, where Embree's
// triangle test and the watertight test round differently; before hits at a ray's own
// origin were skipped alike on both devices (watertight.h, ray_t_min) it was 99.986 %
// (results/nvidia-h100-80gb-hbm3/archive/cpu-gpu-t-min-e4b4b93). The CPU's answers are Embree's,
// whose kernels round by ISA: 65,531 of 65,536 pixels with its AVX2 and AVX-512 kernels
// (AMD EPYC, Xeon), 65,529 (99.989 %) with its SSE kernels (capped by scripts/isa_cap), so
// below AVX2 the bound is 99.98 %. ~40 s on 2 cores: unit_slow.
TEST(HostGpuTracerSlow, PaperFrameWithinAcceptance) {
  const Scene scene = load_scene("paper-cornell");
  RenderSettings s = settings(256, 800);
  s.seed = 0;
  RunReport hr, cr;
  const Film host = host_film(scene, HostGpuTracer(scene), s, {{0, 0, 0, 800}}, hr);
  Film cpu(s.width, s.height, false);
  run::render(scene, s, cpu, cr);
  const test::FilmAgreement a = test::film_agreement(host, cpu);
  const std::string embree_isa = cpu::embree_tbb_facts()["embree"].value("isa_derived", "unknown");
  std::printf("[ INFO     ] paper-cornell 256x256x800 (Embree %s): %.4f%% of pixels within 1e-4 (%zu of %zu), %zu differ, "
              "worst %.3g\n", embree_isa.c_str(), 100.0 * a.share_within(), a.within, a.pixels, a.differ, a.worst);
  EXPECT_GE(a.share_within(), embree_isa == "avx2" || embree_isa == "avx512" ? 0.9999 : 0.9998);
  EXPECT_EQ(hr.paths, cr.paths);
}

}  // namespace
}  // namespace pb::bvh
