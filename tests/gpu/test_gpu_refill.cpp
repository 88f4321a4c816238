// The pixel strategy's refill megakernel (gpu/src/pixel_refill.cu; label gpu, SKIPPED
// without a device): the same film bit for bit as k_pixel on the binary BVH, and the same
// ray counts, at every threshold, block count and path-state home it is built for, on
// scenes with every material kind, next-event estimation or not, bounded paths (the last
// vertex's emitter query) and Russian roulette; the report says when it ran; values of its
// variables it cannot mean are InputErrors naming them.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/scene_io/scene_library.h"
#include "gpu_film_check.h"

namespace pb::gpu {
namespace {

struct RefillCase {
  const char* scene;
  Sampling sampling;
  int bounces;  // -1: unbounded with Russian roulette
};

bool refill_of(const RunReport& r) { return r.extra["pixel_occupancy"]["refill"].get<bool>(); }

void clear_env() {
  for (const char* v : {"PATHBENCH_GPU_PIXEL_REFILL", "PATHBENCH_GPU_PIXEL_REFILL_MIN", "PATHBENCH_GPU_PIXEL_BLOCKS",
                        "PATHBENCH_GPU_PIXEL_PARKED"})
    ::unsetenv(v);
}

TEST(GpuPixelRefill, SameFilmAndRaysAsThePixelKernel) {
  PB_REQUIRE_GPU();
  clear_env();
  for (const RefillCase& rc : {RefillCase{"paper-cornell-ico:3", Sampling::Nee, 2},
                               RefillCase{"cornell-box:glass", Sampling::Cosine, 3},
                               RefillCase{"cornell-box:spheres", Sampling::Nee, -1},
                               RefillCase{"cornell-box:ggx", Sampling::Nee, 4}}) {
    const Scene scene = load_scene(rc.scene);
    GpuBvhOptions o;
    o.layout = bvh::GpuBvhLayout::Binary;
    const GpuScene gs(scene, o);
    RenderSettings s = small_settings(Strategy::Pixel, 48, 40);  // 40 spp: runs of a pixel end mid-range
    s.sampling = rc.sampling;
    s.max_bounces = rc.bounces;
    RunReport base_r;
    const Film base = render_gpu(scene, gs, s, &base_r);
    EXPECT_FALSE(refill_of(base_r)) << rc.scene << ": auto";
    ::setenv("PATHBENCH_GPU_PIXEL_REFILL", "1", 1);
    for (const char* blocks : {"5", "8"})
      for (const char* parked : {"0", "1"})
        for (const char* min_active : {"1", "16", "32"}) {
          ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", blocks, 1);
          ::setenv("PATHBENCH_GPU_PIXEL_PARKED", parked, 1);
          ::setenv("PATHBENCH_GPU_PIXEL_REFILL_MIN", min_active, 1);
          const std::string what = std::string(rc.scene) + ": refill at " + blocks + " blocks, parked " + parked +
                                   ", threshold " + min_active;
          RunReport r;
          expect_identical(base, render_gpu(scene, gs, s, &r), what.c_str());
          EXPECT_TRUE(refill_of(r)) << what;
          EXPECT_EQ(r.extra["pixel_occupancy"]["refill_min_active"], std::stoi(min_active)) << what;
          EXPECT_EQ(r.rays.camera, base_r.rays.camera) << what;
          EXPECT_EQ(r.rays.bounce, base_r.rays.bounce) << what;
          EXPECT_EQ(r.rays.shadow, base_r.rays.shadow) << what;
        }
    clear_env();
  }
}

TEST(GpuPixelRefill, OnlyTheBinaryBvhAndClearRefusals) {
  PB_REQUIRE_GPU();
  clear_env();
  const Scene scene = load_scene("paper-cornell");  // auto: the rects layout
  const GpuScene gs(scene);
  const RenderSettings s = small_settings(Strategy::Pixel, 32, 8);
  ::setenv("PATHBENCH_GPU_PIXEL_REFILL", "1", 1);
  RunReport r;
  render_gpu(scene, gs, s, &r);
  EXPECT_FALSE(refill_of(r)) << "rects layout";
  ::setenv("PATHBENCH_GPU_PIXEL_REFILL", "yes", 1);
  expect_refused_naming(scene, gs, s, "PATHBENCH_GPU_PIXEL_REFILL");
  ::setenv("PATHBENCH_GPU_PIXEL_REFILL", "1", 1);
  for (const char* bad : {"0", "33", "x", "-1", ""}) {
    ::setenv("PATHBENCH_GPU_PIXEL_REFILL_MIN", bad, 1);
    expect_refused_naming(scene, gs, s, "PATHBENCH_GPU_PIXEL_REFILL_MIN");
  }
  clear_env();
}

}  // namespace
}  // namespace pb::gpu
