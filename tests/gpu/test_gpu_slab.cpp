// The slab test's entry, exit and far end on the device (bvh/hit_tests.h slab_entry, slab_exit,
// slab_far: Hopper's three-input integer max / min and add-min on the floats' bits) against the
// host's forms, where the two may differ: slab distances of -0 (ray origins exactly on a box
// plane, or at 0) and of huge magnitude (direction components of 0: 1 / d is +-1e30). Ray by
// ray, closest hits and any-hits, on every layout whose node test uses them, the device
// answers as the host: the same triangle at the same t, bit for bit (label gpu; SKIPPED
// without a device). (The far end's bounds on the host: test_slab.cpp.)
// (Random rays and rays at edges: test_gpu.cpp, GpuTraversal.DeviceMatchesHostAndEmbree.)
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/gpu/render.h"
#include "require_gpu.h"

namespace pb::gpu {
using namespace pb::bvh;  // the BVH library (bvh/) the tracer under test uses
namespace {

// Origins inside the scene's box with one coordinate moved onto its lower plane, or to 0, in
// turn (or none), each sending a ray along the 26 axis, face-diagonal and diagonal directions.
std::vector<TraceQuery> plane_and_axis_rays(const Scene& scene, int origins) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(0.05f, 0.95f);
  const Vec3f lo = scene.bounds_min, ext = scene.bounds_max - scene.bounds_min;
  std::vector<TraceQuery> q;
  for (int n = 0; n < origins; ++n) {
    float o[3] = {lo.x + ext.x * u(rng), lo.y + ext.y * u(rng), lo.z + ext.z * u(rng)};
    const float plane[3] = {lo.x, lo.y, lo.z};
    const int k = n % 4;
    if (k < 3) o[k] = (n / 4) % 2 ? plane[k] : 0.0f;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          if (dx || dy || dz) q.push_back({{o[0], o[1], o[2]}, {float(dx), float(dy), float(dz)},
                         std::numeric_limits<float>::infinity()});
  }
  return q;
}

TEST(GpuSlab, DeviceMatchesHostOnPlanesAndAxes) {
  PB_REQUIRE_GPU();
  const Scene scene = load_scene("paper-cornell-ico:3");
  const std::vector<TraceQuery> rays = plane_and_axis_rays(scene, 400);
  for (GpuBvhLayout layout : {GpuBvhLayout::Binary, GpuBvhLayout::Wide8, GpuBvhLayout::Leaves}) {
    GpuBvhOptions options;
    options.layout = layout;
    const SceneBvhHost bvh = build_scene_bvh(scene, options);
    const auto closest = trace_on_device(scene, rays, false, options);
    const auto any = trace_on_device(scene, rays, true, options);
    size_t hits = 0, closest_differ = 0, any_differ = 0;
    std::string first;
    for (size_t i = 0; i < rays.size(); ++i) {
      float t = 0;
      const uint32_t prim = traverse<false>(bvh.view(), rays[i].o, rays[i].d, rays[i].t_max, t);
      const bool same = closest[i].prim == prim && (prim == kNoHit || std::memcmp(&closest[i].t, &t, sizeof t) == 0);
      hits += prim != kNoHit;
      if (!same && first.empty()) {
        char buf[300];
        std::snprintf(buf, sizeof buf, "o=(%.9g,%.9g,%.9g) d=(%g,%g,%g): device prim %u t %.9g, host prim %u t %.9g",
                      rays[i].o.x, rays[i].o.y, rays[i].o.z, rays[i].d.x, rays[i].d.y, rays[i].d.z, closest[i].prim,
                      closest[i].t, prim, t);
        first = buf;
      }
      closest_differ += !same;
      float ta;
      any_differ += (any[i].prim == kNoHit) != (traverse<true>(bvh.view(), rays[i].o, rays[i].d, rays[i].t_max, ta) == kNoHit);
    }
    std::printf("[ INFO     ] %s: %zu rays on planes and axes, %zu hit; device vs host: %zu closest, %zu any-hit differ\n",
                to_string(layout), rays.size(), hits, closest_differ, any_differ);
    EXPECT_GT(hits, rays.size() / 2) << to_string(layout);
    EXPECT_EQ(closest_differ, 0u) << to_string(layout) << ": " << first;
    EXPECT_EQ(any_differ, 0u) << to_string(layout);
  }
}

}  // namespace
}  // namespace pb::gpu
