// --instancing on the GPU (label gpu; SKIPPED without a device): the two-level BVH
// (gpu/two_level_bvh.h) gives the flat BVH's film byte for byte, for both strategies,
// and HostGpuTracer's (the same code on the CPU: tests/gpu/test_two_level.cpp); ray by
// ray the device's two-level traversal answers as the host's.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/bvh/host_tracer.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/gpu/render.h"
#include "refusal_check.h"
#include "require_gpu.h"

namespace pb::gpu {
using namespace pb::bvh;  // the BVH library (bvh/) the tracer under test uses
namespace {

const std::string kRoot = std::string(PATHBENCH_SOURCE_DIR) + "/";

Scene quiet_load(const std::string& path) {
  testing::internal::CaptureStderr();
  Scene s = load_scene(kRoot + path);
  testing::internal::GetCapturedStderr();
  return s;
}

Film gpu_film(const Scene& scene, const GpuScene& gs, const RenderSettings& s, RunReport& r) {
  Film f(s.width, s.height, false);
  f.begin(s.spp, scene.max_emission());
  render(scene, gs, s, f, r, false);
  return f;
}

TEST(GpuInstancing, FilmsEqualFlatAndHost) {
  PB_REQUIRE_GPU();
  if (GpuBvhOptions::from_env().layout == GpuBvhLayout::Leaves)  // run_on_device.sh's per-layout ctest
    GTEST_SKIP() << "PATHBENCH_GPU_BVH=leaves refuses scenes with instances (bvh_layout.h)";
  for (const char* name : {"scenes/examples/instancing.json", "tests/data/scenes/instances/grid-125.json",
                           "tests/data/scenes/formats/instanced.xml", "tests/data/scenes/formats/instanced.gltf",
                           "scenes/examples/pyramids.gltf"}) {
    const Scene scene = quiet_load(name);
    const GpuScene flat(scene, Instancing::Off), inst(scene, Instancing::On);
    for (Strategy strategy : {Strategy::Pixel, Strategy::Wavefront})
      for (Precision precision : {Precision::Float, Precision::Double}) {
        if (strategy != Strategy::Pixel && precision == Precision::Double) continue;  // the GPU's double is pixel only
        SCOPED_TRACE(testing::Message() << name << " " << to_string(strategy) << " " << to_string(precision));
        RenderSettings s;
        s.width = 96;
        s.height = 72;
        s.spp = 8;
        s.device = Device::Gpu;
        s.strategy = strategy;
        s.precision = precision;
        s.seed = 21;
        s.progress = false;
        RunReport rf, ri, rh;
        s.instancing = Instancing::Off;
        const Film a = gpu_film(scene, flat, s, rf);
        s.instancing = Instancing::On;
        const Film b = gpu_film(scene, inst, s, ri);
        EXPECT_EQ(a.raw_sums(), b.raw_sums());
        EXPECT_EQ(rf.extra["instancing"]["used"], false);
        EXPECT_EQ(ri.extra["instancing"]["used"], true);
        if (strategy == Strategy::Pixel) {  // HostGpuTracer is the pixel megakernel's loop
          Film h(s.width, s.height, false);
          h.begin(s.spp, scene.max_emission());
          HostGpuTracer(scene, Instancing::On).render(s, h, rh);
          EXPECT_EQ(h.raw_sums(), b.raw_sums());
        }
      }
  }
}

// A scene with instances traced flat runs the binary BVH's exact-ties megakernels, compiled for
// 3 and 8 blocks only (pixel.cu): PATHBENCH_GPU_PIXEL_BLOCKS=5 or 6 is refused, naming the
// variable, where it once ran 3 blocks and reported the count asked; long paths leave auto at 3
// (the 5-block rule is the plain binary BVH's).
TEST(GpuInstancing, FlatBlocksAsCompiled) {
  PB_REQUIRE_GPU();
  const Scene scene = quiet_load("scenes/examples/instancing.json");
  const GpuScene flat(scene, Instancing::Off);
  RenderSettings s;
  s.width = s.height = 16;
  s.spp = 4;
  s.max_bounces = 8;
  s.device = Device::Gpu;
  s.seed = 21;
  s.progress = false;
  RunReport r;
  ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
  gpu_film(scene, flat, s, r);
  EXPECT_EQ(r.extra["pixel_occupancy"]["min_blocks_per_sm"], 3) << r.extra["pixel_occupancy"]["why"];
  for (const char* blocks : {"5", "6"}) {
    SCOPED_TRACE(testing::Message() << "PATHBENCH_GPU_PIXEL_BLOCKS=" << blocks);
    ::setenv("PATHBENCH_GPU_PIXEL_BLOCKS", blocks, 1);
    ::pb::test::expect_refused_naming(scene, flat, s, "PATHBENCH_GPU_PIXEL_BLOCKS");
  }
  ::unsetenv("PATHBENCH_GPU_PIXEL_BLOCKS");
}

TEST(GpuInstancing, DeviceTraversalAnswersAsTheHost) {
  PB_REQUIRE_GPU();
  const Scene s = quiet_load("tests/data/scenes/instances/grid-125.json");
  GpuBvhOptions o;
  o.instancing = Instancing::On;
  const SceneBvhHost host = build_scene_bvh(s, o);
  std::mt19937 rng(5);
  std::uniform_int_distribution<uint32_t> tri(0, uint32_t(s.triangles.size() - 1));
  std::vector<TraceQuery> rays;
  for (int i = 0; i < 20000; ++i) {
    const Triangle& t = s.triangles[tri(rng)];
    const Vec3f to = i % 2 ? s.positions[t.v[0]] : (s.positions[t.v[1]] + s.positions[t.v[2]]) * 0.5f;
    rays.push_back({s.camera.position, normalize(to - s.camera.position), 1e30f});
  }
  for (bool any : {false, true}) {
    const std::vector<TraceResult> dev = trace_on_device(s, rays, any, o);
    int differ = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      float t = 0;
      const uint32_t h = any ? traverse<true>(host.view(), rays[i].o, rays[i].d, rays[i].t_max, t)
                             : traverse<false>(host.view(), rays[i].o, rays[i].d, rays[i].t_max, t);
      differ += (h == kNoHit) != (dev[i].prim == kNoHit) || (!any && (h != dev[i].prim || t != dev[i].t));
    }
    EXPECT_EQ(differ, 0) << (any ? "any hit" : "closest hit");
  }
}

}  // namespace
}  // namespace pb::gpu
