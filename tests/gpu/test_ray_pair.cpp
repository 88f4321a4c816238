// The paired walk (ray_pair.h) and the paired path loop (path_trace.h) that the binary BVH's
// megakernels run: each ray answered as traverse() answers it alone, and every path's
// radiance and ray counts the one-ray-at-a-time loop's, bit for bit. (That the GPU's films
// are the host tracer's, byte for byte, is test_gpu.cpp's, label gpu.)
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <string>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/bvh/path_trace.h"
#include "pathbench/bvh/ray_pair.h"
#include "pathbench/common/features.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb::bvh {
namespace {

const std::string kInstancing = std::string(PATHBENCH_SOURCE_DIR) + "/scenes/examples/instancing.json";
const std::string kMaterials = std::string(PATHBENCH_SOURCE_DIR) + "/scenes/suite/cornell-materials.json";

SceneBvhHost binary_bvh(const Scene& scene) {
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Binary;
  return build_scene_bvh(scene, o);
}

template <bool kWatertight, int kKind>
void check_pairs(const Scene& scene, const BvhView& view, int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> n;
  const Vec3f ext = scene.bounds_max - scene.bounds_min;
  auto point = [&] {
    return scene.bounds_min + Vec3f{ext.x * (0.02f + 0.96f * u(rng)), ext.y * (0.02f + 0.96f * u(rng)),
                                    ext.z * (0.02f + 0.96f * u(rng))};
  };
  int blocked = 0, hits = 0;
  for (int i = 0; i < count; ++i) {
    const Vec3f o0 = point(), d0 = point() - o0;  // a segment between two points of the scene
    const Vec3f o1 = point(), d1{n(rng), n(rng), n(rng)};
    const Vec3f d1s = point() - o1;
    const bool has_first = i % 5 != 0;
    const SecondRay kind = SecondRay(i % 3);
    const Vec3f& second_d = kind == SecondRay::Shadow ? d1s : d1;
    const PairAnswer a = trace_pair<kWatertight, kKind>(view, has_first, o0, d0, kind, o1, second_d);
    const bool first = has_first && occluded<kWatertight>(view, o0, d0, 1.0f);
    ASSERT_EQ(a.first_blocked, first) << "ray pair " << i;
    blocked += first;
    if (kind == SecondRay::None) {
      ASSERT_EQ(a.hit, kNoHit) << "ray pair " << i;
      continue;
    }
    float t = 0.0f;
    const uint32_t hit = kind == SecondRay::Shadow ? traverse<true, kWatertight>(view, o1, second_d, 1.0f, t)
                                                   : traverse<false, kWatertight>(view, o1, second_d, kInf, t);
    ASSERT_EQ(a.hit, hit) << "ray pair " << i;
    if (hit != kNoHit) {
      ASSERT_EQ(std::bit_cast<uint32_t>(a.t), std::bit_cast<uint32_t>(t)) << "ray pair " << i;
      ++hits;
    }
  }
  // The rays must exercise both answers.
  EXPECT_GT(blocked, count / 20);
  EXPECT_GT(hits, count / 10);
}

TEST(RayPair, EachRayAnsweredAsAlone) {
  for (const std::string& name : {std::string("paper-cornell-ico:3"), kMaterials}) {
    SCOPED_TRACE(name);
    const Scene scene = load_scene(name);
    const SceneBvhHost bvh = binary_bvh(scene);
    ASSERT_EQ(bvh.view().binary.exact_ties, 0u);
    check_pairs<true, int(TraversalKind::Binary)>(scene, bvh.view(), 20000);
    check_pairs<false, int(TraversalKind::Binary)>(scene, bvh.view(), 5000);
  }
  // A scene with instances traced flat: the least (t, id) tie rule.
  const Scene inst = load_scene(kInstancing);
  const SceneBvhHost bvh = binary_bvh(inst);
  ASSERT_EQ(bvh.view().binary.exact_ties, 1u);
  check_pairs<true, kBinaryExactTies>(inst, bvh.view(), 20000);
  // Other layouts trace the pair one ray after the other.
  const Scene ico = load_scene("paper-cornell-ico:3");
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Wide8;
  const SceneBvhHost wide = build_scene_bvh(ico, o);
  check_pairs<true, int(TraversalKind::Wide)>(ico, wide.view(), 5000);
}

struct PathCase {
  std::string scene;
  int32_t bounces;
  Sampling sampling;
};

// Every sample of a small frame through the paired loop and through the one-ray-at-a-time one.
void check_paths(const PathCase& pc) {
  SCOPED_TRACE(pc.scene + " bounces " + std::to_string(pc.bounces));
  const Scene scene = load_scene(pc.scene);
  const SceneBvhHost bvh = binary_bvh(scene);
  const BvhView view = bvh.view();
  const SceneView sv = scene.view();
  RenderSettings rs;
  rs.width = rs.height = 16;
  rs.spp = 24;
  rs.max_bounces = pc.bounces;
  rs.sampling = pc.sampling;
  rs.seed = 5;
  rs.russian_roulette = pc.bounces < 0;
  const PathConfig c = rs.path_config();
  uint64_t shadow = 0, nonzero = 0;
  with_features(sv.material_kinds, [&](auto kinds) {
    constexpr uint32_t K = decltype(kinds)::value;
    with_traversal_kind(view, [&](auto kind) {
      constexpr int B = decltype(kind)::value;
      if constexpr (B == int(TraversalKind::Binary) || B == kBinaryExactTies) {
        for (uint32_t pixel = 0; pixel < rs.width * rs.height; ++pixel)
          for (uint32_t k = 0; k < rs.spp; ++k) {
            uint32_t b0 = 0, s0 = 0, b1 = 0, s1 = 0;
            PathState<float> st0, st1;
            ShadowQuery<float> q0, q1;
            const Vec3f one = trace_path_one_ray_at_a_time<K, float, true, kAnyKind>(sv, view, c, pixel, k, b0, s0, st0, q0);
            const Vec3f two = trace_path_paired<K, float, true, B>(sv, view, c, pixel, k, b1, s1, st1, q1);
            ASSERT_EQ(std::bit_cast<uint32_t>(one.x), std::bit_cast<uint32_t>(two.x)) << pixel << " " << k;
            ASSERT_EQ(std::bit_cast<uint32_t>(one.y), std::bit_cast<uint32_t>(two.y)) << pixel << " " << k;
            ASSERT_EQ(std::bit_cast<uint32_t>(one.z), std::bit_cast<uint32_t>(two.z)) << pixel << " " << k;
            ASSERT_EQ(b0, b1) << pixel << " " << k;
            ASSERT_EQ(s0, s1) << pixel << " " << k;
            shadow += s0;
            nonzero += one.x > 0.0f || one.y > 0.0f || one.z > 0.0f;
          }
      } else {
        FAIL() << "not the binary layout";
      }
    });
  });
  if (pc.sampling == Sampling::Nee && pc.bounces != 0) EXPECT_GT(shadow, 0u);
  EXPECT_GT(nonzero, 0u);
}

TEST(RayPair, PathsAsOneRayAtATime) {
  check_paths({"paper-cornell-ico:3", 2, Sampling::Nee});
  check_paths({"paper-cornell-ico:3", 0, Sampling::Nee});
  check_paths({"paper-cornell-ico:3", 3, Sampling::Uniform});
  check_paths({"paper-cornell-ico:3", -1, Sampling::Nee});  // unbounded: roulette ends paths after a shadow ray
  check_paths({kMaterials, 8, Sampling::Nee});  // glass and mirrors: bounces without shadow rays
  check_paths({kInstancing, 2, Sampling::Nee});  // the exact tie rule
}

}  // namespace
}  // namespace pb::bvh
