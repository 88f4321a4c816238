// Host-side checks of the GPU tracer's BVH (built by Embree's builder) and its
// host+device traversal with the watertight triangle test, against Embree's own
// intersector on the same rays. Runs without a GPU (CTest label `unit`).
#include <gtest/gtest.h>

#include <cstdio>
#include <ostream>
#include <random>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/gpu/bvh_build.h"
#include "traversal_check.h"

namespace pb::gpu {
namespace {

using test::Agreement;
using test::EmbreeReference;
using test::Hit;
using test::Ray3;

struct SceneCase {
  const char* name;
  bool closed;  // every ray from inside must hit something
};

void PrintTo(const SceneCase& c, std::ostream* os) { *os << c.name << (c.closed ? " (closed)" : ""); }

Scene load_or_skip(const char* name, bool& ok) {
  ok = true;
  try {
    return load_scene(name);
  } catch (const InputError&) {
    ok = false;
    return {};
  }
}

Hit trace_host(const BvhHost& bvh, const Ray3& r) {
  Hit h;
  h.prim = traverse<false>(bvh.view(), r.o, r.d, r.t_max, h.t);
  return h;
}

class Traversal : public ::testing::TestWithParam<SceneCase> {
 protected:
  void SetUp() override {
    bool ok;
    scene_ = load_or_skip(GetParam().name, ok);
    if (!ok) GTEST_SKIP() << "scene " << GetParam().name << " is not built in yet";
    bvh_ = build_bvh(scene_);
    // Origins strictly inside the scene's bounds.
    const Vec3f ext = scene_.bounds_max - scene_.bounds_min;
    lo_ = scene_.bounds_min + ext * 0.02f;
    hi_ = scene_.bounds_max - ext * 0.02f;
  }
  Scene scene_;
  BvhHost bvh_;
  Vec3f lo_, hi_;
};

TEST_P(Traversal, BvhReferencesEveryTriangle) {
  std::vector<int> seen(scene_.triangles.size(), 0);
  for (const BvhTriangle& t : bvh_.tris) {
    ASSERT_LT(t.prim, scene_.triangles.size());
    seen[t.prim] = 1;
  }
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_TRUE(seen[i]) << "triangle " << i << " is in no leaf";
  EXPECT_FALSE(is_leaf(0));
  EXPECT_LT(bvh_.depth + 1, uint32_t(kTraversalStackSize));
  std::printf("[ INFO     ] %s: %zu triangles, %zu nodes, %u leaves, depth %u, SAH cost %.2f, built in %.3f s\n",
              GetParam().name, scene_.triangles.size(), bvh_.nodes.size(), bvh_.leaves, bvh_.depth, bvh_.sah_cost,
              bvh_.build_seconds);
}

TEST_P(Traversal, RandomRaysAgreeWithEmbree) {
  const EmbreeReference ref(scene_);
  const auto rays = test::random_rays(lo_, hi_, 20000, 7);
  Agreement a;
  for (const Ray3& r : rays) a.add(r, trace_host(bvh_, r), ref.closest(r));
  std::printf("[ INFO     ] %s random: %zu rays, %zu hit/miss, %zu prim (%zu not ties), %zu t mismatches, %zu misses\n",
              GetParam().name, a.rays, a.hit_miss_mismatch, a.prim_mismatch, a.prim_mismatch_not_tie, a.t_mismatch,
              a.misses);
  EXPECT_EQ(a.hit_miss_mismatch, 0u) << a.first_problem;
  EXPECT_EQ(a.prim_mismatch_not_tie, 0u) << a.first_problem;
  EXPECT_EQ(a.t_mismatch, 0u) << a.first_problem;
  if (GetParam().closed) EXPECT_EQ(a.misses, 0u);
}

TEST_P(Traversal, RaysThroughEdgesAndVerticesNeverPassBetweenTriangles) {
  const EmbreeReference ref(scene_);
  const auto rays = test::edge_and_vertex_rays(scene_, lo_, hi_, 24, 11);
  Agreement a;
  a.edge_rays = true;
  size_t ref_misses_we_hit = 0;
  for (const Ray3& r : rays) {
    const Hit ours = trace_host(bvh_, r), theirs = ref.closest(r);
    if (theirs.prim == kNoHit && ours.prim != kNoHit) {
      ++ref_misses_we_hit;  // Embree (not in robust mode) may slip through an edge
      continue;
    }
    a.add(r, ours, theirs, test::hit_cos(scene_, r, ours));
  }
  std::printf("[ INFO     ] %s edges/vertices: %zu rays, %zu hit/miss, %zu prim (%zu not ties), %zu t mismatches, "
              "%zu misses; Embree missed %zu that we hit; %zu differ only at the aimed-at edge; %zu grazing\n",
              GetParam().name, a.rays, a.hit_miss_mismatch, a.prim_mismatch, a.prim_mismatch_not_tie, a.t_mismatch,
              a.misses, ref_misses_we_hit, a.at_target_edge, a.grazing);
  if (GetParam().closed) EXPECT_EQ(a.misses, 0u) << "a ray slipped between triangles";
  EXPECT_EQ(a.hit_miss_mismatch, 0u) << a.first_problem;
  EXPECT_EQ(a.prim_mismatch_not_tie, 0u) << a.first_problem;
  EXPECT_EQ(a.t_mismatch, 0u) << a.first_problem;
}

TEST_P(Traversal, OcclusionAgreesWithEmbree) {
  const EmbreeReference ref(scene_);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  size_t n = 20000, mismatches = 0, occluded_count = 0;
  for (size_t i = 0; i < n; ++i) {
    auto point = [&] {
      return Vec3f{lo_.x + (hi_.x - lo_.x) * u(rng), lo_.y + (hi_.y - lo_.y) * u(rng), lo_.z + (hi_.z - lo_.z) * u(rng)};
    };
    const Vec3f a = point(), b = point();
    const Ray3 r{a, b - a, 1.0f};
    const bool ours = occluded(bvh_.view(), r.o, r.d, 1.0f);
    occluded_count += ours;
    if (ours != ref.occluded(r)) ++mismatches;
  }
  std::printf("[ INFO     ] %s occlusion: %zu segments, %zu occluded, %zu disagree with Embree\n", GetParam().name, n,
              occluded_count, mismatches);
  EXPECT_LE(mismatches, n / 10000);  // only segments ending within rounding of a surface
}

INSTANTIATE_TEST_SUITE_P(Scenes, Traversal,
                         ::testing::Values(SceneCase{"paper-cornell", true}, SceneCase{"paper-cornell-ico:3", true},
                                           SceneCase{"cornell-box", false}),
                         [](const auto& info) {
                           std::string n = info.param.name;
                           for (char& c : n)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return n;
                         });

// A square split into four triangles around its centre: rays exactly through the shared
// centre vertex and through points of the shared diagonals hit at least one triangle.
TEST(Watertight, SharedEdgesAndVertexOfAFan) {
  const Vec3f centre{0.0f, 0.0f, 0.0f};
  const Vec3f corner[4] = {{-1.0f, -1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {-1.0f, 1.0f, 0.0f}};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int misses = 0;
  for (int i = 0; i < 40000; ++i) {
    const float s = 0.9f * u(rng);
    Vec3f target = centre;
    if (i % 3 == 1) target = {s, s, 0.0f};
    if (i % 3 == 2) target = {s, -s, 0.0f};
    const Vec3f o{u(rng) * 3.0f, u(rng) * 3.0f, (i & 1 ? 1.0f : -1.0f) * (0.5f + 2.0f * std::fabs(u(rng)))};
    const Vec3f dir = target - o;
    const WatertightRay wr = make_watertight_ray(o, dir);
    int hits = 0;
    for (int k = 0; k < 4; ++k) {
      float t = 0;
      if (intersect_watertight(wr, centre, corner[k], corner[(k + 1) % 4], 1e30f, t)) {
        ++hits;
        EXPECT_NEAR(t, 1.0f, 1e-5f);
      }
    }
    if (hits == 0) ++misses;
  }
  EXPECT_EQ(misses, 0);
}

TEST(Watertight, RespectsTheInterval) {
  const Vec3f a{-1, -1, 0}, b{1, -1, 0}, c{0, 1, 0};
  const WatertightRay wr = make_watertight_ray({0, 0, 2}, {0, 0, -1});
  float t = 0;
  EXPECT_TRUE(intersect_watertight(wr, a, b, c, 3.0f, t));
  EXPECT_FLOAT_EQ(t, 2.0f);
  EXPECT_FALSE(intersect_watertight(wr, a, b, c, 2.0f, t));  // t_max is exclusive
  const WatertightRay away = make_watertight_ray({0, 0, 2}, {0, 0, 1});
  EXPECT_FALSE(intersect_watertight(away, a, b, c, 1e30f, t));  // behind the origin
}

TEST(Bvh, EmptySceneMissesEverything) {
  Scene s;
  s.name = "empty";
  const BvhHost bvh = build_bvh(s);
  float t;
  EXPECT_EQ(traverse<false>(bvh.view(), {0, 0, 0}, {0, 0, 1}, 1e30f, t), kNoHit);
  EXPECT_FALSE(occluded(bvh.view(), {0, 0, 0}, {1, 1, 1}, 1.0f));
}

}  // namespace
}  // namespace pb::gpu
