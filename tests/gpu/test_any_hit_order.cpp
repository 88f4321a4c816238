// The binary BVH's any-hit (shadow) walks take the farther child first (binary_bvh.h,
// traverse's kFarFirst): the same answers as the closest-hit walk's, segment by segment,
// through other nodes than the nearer-first walk's. Plain C++ (label unit); the device runs
// the same function (GpuSlab and GpuTraversal check its any-hits against the host's).
#include <gtest/gtest.h>

#include <random>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb::bvh {
namespace {

TEST(AnyHitOrder, FarFirstAnswersAsTheClosestHitThroughOtherNodes) {
  for (const char* name : {"paper-cornell-ico:3", "paper-cornell-ico:5"}) {
    const Scene scene = load_scene(name);
    const SceneBvhHost b = build_scene_bvh(scene, GpuBvhOptions{});
    ASSERT_EQ(b.layout, GpuBvhLayout::Binary) << name;
    const BinaryBvhView v = b.view().binary;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.02f, 0.98f);
    const Vec3f lo = scene.bounds_min, ext = scene.bounds_max - scene.bounds_min;
    auto point = [&] { return Vec3f{lo.x + ext.x * u(rng), lo.y + ext.y * u(rng), lo.z + ext.z * u(rng)}; };
    size_t blocked = 0, differ = 0, other_nodes = 0;
    const size_t n = 20000;
    for (size_t i = 0; i < n; ++i) {  // segments between points inside the box: t < 1
      const Vec3f from = point(), d = point() - from;
      float t_any = 0, t_closest = 0;
      TraversalStats any;
      const bool hit = traverse<true>(v, from, d, 1.0f, t_any, &any) != kNoHit;
      blocked += hit;
      differ += hit != (traverse<false>(v, from, d, 1.0f, t_closest) != kNoHit);
      // The nearer-first walk of the same query (traverse's kFarFirst = false).
      float t_near = 0;
      TraversalStats near;
      const uint32_t prim = traverse<true, true, -1, false>(v, from, d, 1.0f, t_near, &near);
      differ += hit != (prim != kNoHit);
      other_nodes += near.nodes != any.nodes;
    }
    EXPECT_EQ(differ, 0u) << name;
    EXPECT_GT(blocked, n / 20) << name;  // both answers occur
    EXPECT_LT(blocked, n - n / 20) << name;
    EXPECT_GT(other_nodes, n / 20) << name;  // and the order changes the walks
  }
}

}  // namespace
}  // namespace pb::bvh
