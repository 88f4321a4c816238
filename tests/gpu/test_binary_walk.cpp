// The binary BVH's walk in steps (binary_walk.h, the GPU refill megakernel's) against the
// walk in one go (binary_bvh.h's traverse): the same triangle and, for any-hit queries,
// the same answer on every ray, closest and shadow-like segments, on a mesh in a box and on
// the box alone. Runs without a GPU (CTest label `unit`).
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "pathbench/bvh/binary_walk.h"
#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/scene_io/scene_library.h"
#include "traversal_check.h"

namespace pb::bvh {
namespace {

using test::Ray3;

void expect_same_answers(const char* name) {
  const Scene scene = load_scene(name);
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Binary;
  const SceneBvhHost host = build_scene_bvh(scene, o);
  const BinaryBvhView bvh = host.binary.view();
  const Vec3f ext = scene.bounds_max - scene.bounds_min;
  const std::vector<Ray3> rays =
      test::random_rays(scene.bounds_min + ext * 0.02f, scene.bounds_max - ext * 0.02f, 20000, 7);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.05f, 3.0f);
  size_t hits = 0, occluded = 0, steps = 0;
  for (const Ray3& r : rays) {
    float t;
    const uint32_t closest = traverse<false, true, 0>(bvh, r.o, r.d, r.t_max, t);
    ASSERT_EQ(walk_to_end(bvh, r.o, r.d, r.t_max, false), closest) << name;
    hits += closest != kNoHit;
    // A segment of random length, as a shadow ray's (t_max 1 along an unnormalised direction).
    const Vec3f seg = r.d * u(rng);
    const bool blocked = traverse<true, true, 0>(bvh, r.o, seg, 1.0f, t) != kNoHit;
    ASSERT_EQ(walk_to_end(bvh, r.o, seg, 1.0f, true) != kNoHit, blocked) << name;
    occluded += blocked;
    BinaryWalk w;
    uint32_t stack[kTraversalStackSize];
    w.begin(r.o, r.d, r.t_max, false);
    for (++steps; !w.step(bvh, stack); ++steps) {
    }
  }
  // The rays ask something of the BVH: most hit, some segments are blocked and some not,
  // and some walks take more than one step (leaf).
  EXPECT_GT(hits, rays.size() * 9 / 10) << name;
  EXPECT_GT(occluded, rays.size() / 20) << name;
  EXPECT_LT(occluded, rays.size()) << name;
  EXPECT_GT(steps, rays.size()) << name;
}

TEST(BinaryWalk, StepsGiveTraversesAnswers) {
  expect_same_answers("paper-cornell-ico:3");
  expect_same_answers("paper-cornell");
}

}  // namespace
}  // namespace pb::bvh
