// The GPU's two-level BVH (--instancing; gpu/two_level_bvh.h), on the CPU: ray by ray it
// names the flat BVH's triangle with the flat BVH's t (the triangles are tested in world
// space by the same function, and the closest hit is the least (t, id) whichever order
// they come in), and HostGpuTracer's films, instanced and flat, are byte for byte equal.
// The GPU's own films: TwoLevel.GpuFilmsEqual in test_gpu.cpp (label gpu).
#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>
#include <vector>

#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/bvh/host_tracer.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb::bvh {
namespace {

const std::string kRoot = std::string(PATHBENCH_SOURCE_DIR) + "/";

// Scenes with instances of every reader: JSON (rotated cubes; 125 rotated, unevenly
// scaled and mirrored ico spheres), Mitsuba shapegroups, glTF meshes used by several nodes.
const char* const kScenes[] = {"scenes/examples/instancing.json", "tests/data/scenes/instances/grid-125.json",
                               "tests/data/scenes/formats/instanced.xml", "tests/data/scenes/formats/instanced.gltf",
                               "scenes/examples/pyramids.gltf"};

Scene quiet_load(const std::string& path) {
  testing::internal::CaptureStderr();  // readers' warnings (e.g. unmodelled glTF fields)
  Scene s = load_scene(path);
  testing::internal::GetCapturedStderr();
  return s;
}

SceneBvhHost build(const Scene& s, Instancing i) {
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Binary;
  o.instancing = i;
  return build_scene_bvh(s, o);
}

Vec3f point_on(const Scene& s, uint32_t tri, float u, float v) {
  if (u + v > 1) u = 1 - u, v = 1 - v;
  const Triangle& t = s.triangles[tri];
  const Vec3f a = s.positions[t.v[0]], b = s.positions[t.v[1]], c = s.positions[t.v[2]];
  return a + (b - a) * u + (c - a) * v;
}

// Rays between surface points, to vertices and edge midpoints (where ties and edge
// decisions happen), and from the camera.
struct Query {
  Vec3f o, d;
  float t_max;
};
std::vector<Query> queries(const Scene& s, int n) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<uint32_t> tri(0, uint32_t(s.triangles.size() - 1));
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Query> q;
  for (int i = 0; i < n; ++i) {
    const Vec3f from = i % 3 == 0 ? s.camera.position : point_on(s, tri(rng), u(rng), u(rng));
    const uint32_t t = tri(rng);
    const Triangle& tt = s.triangles[t];
    const Vec3f to = i % 4 == 0   ? s.positions[tt.v[i % 3]]
                     : i % 4 == 1 ? (s.positions[tt.v[0]] + s.positions[tt.v[1]]) * 0.5f
                                  : point_on(s, t, u(rng), u(rng));
    const Vec3f d = to - from;
    if (length(d) == 0) continue;
    q.push_back({from, i % 2 ? d : normalize(d), i % 2 ? 1.0f : std::numeric_limits<float>::infinity()});
  }
  return q;
}

TEST(TwoLevel, SameTriangleAndDistanceAsTheFlatBvh) {
  for (const char* name : kScenes) {
    SCOPED_TRACE(name);
    const Scene s = quiet_load(kRoot + name);
    const SceneBvhHost flat = build(s, Instancing::Off), two = build(s, Instancing::On);
    ASSERT_EQ(two.layout, GpuBvhLayout::TwoLevel);
    ASSERT_EQ(two.view().kind, TraversalKind::TwoLevel);
    EXPECT_GT(two.two_level.instanced, 0u);
    int hits = 0, mismatches = 0;
    for (const Query& r : queries(s, 20000)) {
      float ta = -1, tb = -1;
      const uint32_t a = traverse<false>(flat.view(), r.o, r.d, r.t_max, ta);
      const uint32_t b = traverse<false>(two.view(), r.o, r.d, r.t_max, tb);
      hits += a != kNoHit;
      if (a != b || (a != kNoHit && ta != tb)) ++mismatches;
      if (occluded(flat.view(), r.o, r.d, r.t_max) != occluded(two.view(), r.o, r.d, r.t_max)) ++mismatches;
    }
    EXPECT_GT(hits, 5000);
    EXPECT_EQ(mismatches, 0);
  }
}

TEST(TwoLevel, SmallerThanTheFlatBvhForManyCopies) {
  const Scene s = quiet_load(kRoot + "tests/data/scenes/instances/grid-125.json");
  const SceneBvhHost flat = build(s, Instancing::Off), two = build(s, Instancing::Auto);
  EXPECT_EQ(two.two_level.instanced, 125u);
  EXPECT_EQ(two.two_level.prototypes, 1u);
  EXPECT_EQ(two.two_level.flat_triangles, 4u);  // the floor and the light
  EXPECT_LT(two.bytes() * 20, flat.bytes());
}

TEST(TwoLevel, OnWithoutInstancesTracesFlat) {
  const Scene s = load_scene("paper-cornell");
  const SceneBvhHost b = build(s, Instancing::On);
  EXPECT_EQ(b.layout, GpuBvhLayout::Binary);
  const nlohmann::json r = instancing_report(s, b, Instancing::On);
  EXPECT_EQ(r["used"], false);
  EXPECT_EQ(r["why"], "the scene has no instances: traced flat");
}

RenderSettings settings(uint32_t w, uint32_t h, uint32_t spp, int threads) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.spp = spp;
  s.threads = threads;
  s.seed = 5;
  s.progress = false;
  return s;
}

Film film_of(const Scene& scene, Instancing i, const RenderSettings& s, RunReport& r) {
  Film f(s.width, s.height, false);
  f.begin(s.spp, scene.max_emission());
  RenderSettings c = s;
  c.instancing = i;
  HostGpuTracer(scene, i).render(c, f, r);
  return f;
}

TEST(TwoLevel, HostGpuTracerFilmsEqualFlat) {
  for (const char* name : kScenes) {
    SCOPED_TRACE(name);
    const Scene s = quiet_load(kRoot + name);
    for (auto [w, h, spp, threads] : {std::tuple{24, 18, 4, 1}, std::tuple{40, 30, 2, 2}}) {
      const RenderSettings rs = settings(w, h, spp, threads);
      RunReport ri, rf;
      const Film inst = film_of(s, Instancing::Auto, rs, ri), flat = film_of(s, Instancing::Off, rs, rf);
      EXPECT_EQ(inst.raw_sums(), flat.raw_sums());
      EXPECT_EQ(ri.rays.total(), rf.rays.total());
      EXPECT_EQ(ri.extra["instancing"]["used"], true);
      EXPECT_EQ(rf.extra["instancing"]["used"], false);
    }
  }
}

// Far from the origin the scene is rebased (scene_origin.cpp) while the instances'
// to_world are not: the two-level BVH must follow Scene::origin.
TEST(TwoLevel, FollowsARebasedScene) {
  const Scene s = transformed(quiet_load(kRoot + "scenes/examples/instancing.json"), 1.0f, {3e5f, 0, -2e5f});
  ASSERT_NE(s.origin.x, 0.0f);
  const RenderSettings rs = settings(24, 18, 4, 2);
  RunReport ri, rf;
  EXPECT_EQ(film_of(s, Instancing::On, rs, ri).raw_sums(), film_of(s, Instancing::Off, rs, rf).raw_sums());
  EXPECT_EQ(ri.extra["instancing"]["used"], true);
}

}  // namespace
}  // namespace pb::bvh
