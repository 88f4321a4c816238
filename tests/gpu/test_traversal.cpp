// Host-side checks of the GPU tracer's BVH (built by Embree's builder) and its
// host+device traversal with the watertight triangle test, against Embree's own
// intersector on the same rays, in every layout (binary, wide4, wide8, brute force,
// leaves, rects, rects-binary: bvh_layout.h); the other layouts also against the binary BVH, hit for hit. Runs without a GPU (CTest label `unit`).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "pathbench/bvh/bvh_build.h"
#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "traversal_check.h"

namespace pb::bvh {
namespace {

using test::Agreement;
using test::EmbreeReference;
using test::Hit;
using test::Ray3;

struct SceneCase {
  const char* name;
  bool closed;  // every ray from inside must hit something
  GpuBvhLayout layout = GpuBvhLayout::Binary;
};

void PrintTo(const SceneCase& c, std::ostream* os) {
  *os << c.name << (c.closed ? " (closed)" : "") << " " << to_string(c.layout);
}

Scene load_or_skip(const char* name, bool& ok) {
  ok = true;
  try {
    return load_scene(name);
  } catch (const InputError&) {
    ok = false;
    return {};
  }
}

Hit trace_host(const BvhView& bvh, const Ray3& r, TraversalStats* stats = nullptr) {
  Hit h;
  h.prim = traverse<false>(bvh, r.o, r.d, r.t_max, h.t, stats);
  return h;
}

class Traversal : public ::testing::TestWithParam<SceneCase> {
 protected:
  void SetUp() override {
    bool ok;
    scene_ = load_or_skip(GetParam().name, ok);
    if (!ok) GTEST_SKIP() << "scene " << GetParam().name << " is not built in yet";
    GpuBvhOptions o;
    o.layout = GetParam().layout;
    bvh_ = build_scene_bvh(scene_, o);
    view_ = bvh_.view();
    // Origins strictly inside the scene's bounds.
    const Vec3f ext = scene_.bounds_max - scene_.bounds_min;
    lo_ = scene_.bounds_min + ext * 0.02f;
    hi_ = scene_.bounds_max - ext * 0.02f;
  }
  Scene scene_;
  SceneBvhHost bvh_;
  BvhView view_;
  Vec3f lo_, hi_;
};

TEST_P(Traversal, BvhReferencesEveryTriangle) {
  if (bvh_.layout == GpuBvhLayout::Rects) {  // every triangle in exactly one rectangle, each flat on its group's axis
    std::vector<int> seen(scene_.triangles.size(), 0);
    for (uint32_t i = 0; i < bvh_.rects.size(); ++i) {
      const AxisRect& r = bvh_.rects[i];
      const int k = i < bvh_.rect_groups.end[0] ? 0 : i < bvh_.rect_groups.end[1] ? 1 : 2;
      EXPECT_EQ(r.lo[k], r.hi[k]) << "rectangle " << i;
      ++seen[r.key];
      ++seen[r.other & kRectIdMask];
      EXPECT_LT(r.key, r.other & kRectIdMask);
    }
    EXPECT_EQ(bvh_.rect_groups.end[2], bvh_.rects.size());
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 1) << "triangle " << i;
    return;
  }
  // rects-binary: the rest's triangles, then the rectangles' (each triangle once: checked in
  // RectsBinaryLayout.AutoTakesTheWallsOfARoom).
  const bool binary_tris = bvh_.layout == GpuBvhLayout::Binary || bvh_.layout == GpuBvhLayout::Leaves ||
                           bvh_.layout == GpuBvhLayout::RectsBinary;
  const std::vector<BvhTriangle>& tris = bvh_.layout == GpuBvhLayout::Brute ? bvh_.all
                                         : binary_tris                      ? bvh_.binary.tris
                                                                            : bvh_.wide.tris;
  std::vector<int> seen(scene_.triangles.size(), 0);
  for (const BvhTriangle& t : tris) {
    ASSERT_LT(t.prim, scene_.triangles.size());
    seen[t.prim] = 1;
  }
  for (size_t i = 0; i < seen.size(); ++i) EXPECT_TRUE(seen[i]) << "triangle " << i << " is in no leaf";
  const bool binary = bvh_.layout == GpuBvhLayout::Binary || bvh_.layout == GpuBvhLayout::RectsBinary;
  const uint32_t depth = binary ? bvh_.binary.depth : bvh_.wide.depth;
  if (binary) {
    EXPECT_FALSE(is_leaf(0));
    EXPECT_LT(depth + 1, uint32_t(kTraversalStackSize));
  }
  if (bvh_.layout == GpuBvhLayout::Wide4 || bvh_.layout == GpuBvhLayout::Wide8) {
    EXPECT_EQ(tris.size(), scene_.triangles.size());  // each triangle in exactly one leaf
    EXPECT_LT(depth + 1, uint32_t(kWideStackSize));
  }
  if (bvh_.layout == GpuBvhLayout::Leaves) {  // every triangle slot in exactly one leaf, no inner nodes
    EXPECT_TRUE(bvh_.binary.nodes.empty());
    std::vector<int> slot(tris.size(), 0);
    for (const LeafBox& l : bvh_.leaves)
      for (uint32_t i = leaf_first(l.ref); i < leaf_first(l.ref) + leaf_count(l.ref); ++i) {
        ASSERT_LT(i, tris.size());
        ++slot[i];
        for (const float* v : {tris[i].v0, tris[i].v1, tris[i].v2})
          for (int k = 0; k < 3; ++k) {  // the leaf's box holds its triangles
            EXPECT_LE(l.lo[k], v[k]);
            EXPECT_GE(l.hi[k], v[k]);
          }
      }
    for (size_t i = 0; i < slot.size(); ++i) EXPECT_EQ(slot[i], 1) << "triangle slot " << i;
  }
  std::printf("[ INFO     ] %s %s: %zu triangles, %u nodes of %u bytes, %.2f MB, depth %u (binary: depth %u, %u "
              "leaves, SAH %.2f), built in %.3f s\n",
              GetParam().name, to_string(bvh_.layout), scene_.triangles.size(), bvh_.nodes(), bvh_.node_bytes(),
              bvh_.bytes() / 1e6, depth, bvh_.binary_depth, bvh_.binary_leaves, bvh_.binary_sah, bvh_.build_seconds);
}

TEST_P(Traversal, RandomRaysAgreeWithEmbree) {
  const EmbreeReference ref(scene_);
  const auto rays = test::random_rays(lo_, hi_, 20000, 7);
  Agreement a;
  TraversalStats stats;
  for (const Ray3& r : rays) a.add(r, trace_host(view_, r, &stats), ref.closest(r));
  std::printf("[ INFO     ] %s %s random: %.2f nodes, %.2f triangles a ray\n", GetParam().name, to_string(bvh_.layout),
              double(stats.nodes) / rays.size(), double(stats.tris) / rays.size());
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
    const Hit ours = trace_host(view_, r), theirs = ref.closest(r);
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
    const bool ours = occluded(view_, r.o, r.d, 1.0f);
    occluded_count += ours;
    if (ours != ref.occluded(r)) ++mismatches;
  }
  std::printf("[ INFO     ] %s occlusion: %zu segments, %zu occluded, %zu disagree with Embree\n", GetParam().name, n,
              occluded_count, mismatches);
  EXPECT_LE(mismatches, n / 10000);  // only segments ending within rounding of a surface
}

std::string case_name(const ::testing::TestParamInfo<SceneCase>& info) {
  std::string n = info.param.name;
  if (info.param.layout != GpuBvhLayout::Binary) n += std::string("_") + to_string(info.param.layout);
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

// Brute force only on the small scenes: it tests every triangle for every ray.
INSTANTIATE_TEST_SUITE_P(
    Scenes, Traversal,
    ::testing::Values(SceneCase{"paper-cornell", true}, SceneCase{"paper-cornell-ico:3", true},
                      SceneCase{"cornell-box", false}, SceneCase{"paper-cornell", true, GpuBvhLayout::Wide8},
                      SceneCase{"paper-cornell-ico:3", true, GpuBvhLayout::Wide8},
                      SceneCase{"cornell-box", false, GpuBvhLayout::Wide8},
                      SceneCase{"paper-cornell", true, GpuBvhLayout::Wide4},
                      SceneCase{"paper-cornell-ico:3", true, GpuBvhLayout::Wide4},
                      SceneCase{"cornell-box", false, GpuBvhLayout::Wide4},
                      SceneCase{"paper-cornell", true, GpuBvhLayout::Brute},
                      SceneCase{"paper-cornell", true, GpuBvhLayout::Leaves},
                      SceneCase{"paper-cornell-ico:3", true, GpuBvhLayout::Leaves},
                      SceneCase{"cornell-box", false, GpuBvhLayout::Leaves},
                      SceneCase{"paper-cornell", true, GpuBvhLayout::Rects},
                      SceneCase{"paper-cornell-ico:3", true, GpuBvhLayout::RectsBinary}),
    case_name);

// Every layout against the binary BVH on the same rays, by the rules the Embree
// comparison uses (a different triangle only at the same t, or at the aimed-at edge of
// an edge ray, where Woop's t orders two grazed triangles by the order of the tests);
// where both find the same triangle, the same t bit for bit (the same watertight test
// and plane_distance); the same any-hit answer on every segment.
void expect_same_hits_as_binary(const Scene& scene, GpuBvhLayout layout, const std::string& label) {
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Binary;  // by name: auto is leaves or rects on the small scenes
  const SceneBvhHost binary = build_scene_bvh(scene, o);
  o.layout = layout;
  const SceneBvhHost other = build_scene_bvh(scene, o);
  const Vec3f ext = scene.bounds_max - scene.bounds_min;
  const Vec3f lo = scene.bounds_min + ext * 0.02f, hi = scene.bounds_max - ext * 0.02f;
  const std::vector<Ray3> random = test::random_rays(lo, hi, 20000, 17);
  const std::vector<Ray3> edges = test::edge_and_vertex_rays(scene, lo, hi, 6, 19, 1024);
  Agreement on_random, on_edges;
  on_edges.edge_rays = true;
  size_t hits = 0, t_differs = 0, occlusion_differs = 0, occlusion_at_target_edge = 0, rays = 0;
  for (const Ray3& r : random) on_random.add(r, trace_host(other.view(), r), trace_host(binary.view(), r));
  for (const Ray3& r : edges) {
    const Hit b = trace_host(other.view(), r);
    on_edges.add(r, b, trace_host(binary.view(), r), test::hit_cos(scene, r, b));
  }
  for (const std::vector<Ray3>* set : {&random, &edges})
  for (const Ray3& r : *set) {
    ++rays;
    const Hit a = trace_host(binary.view(), r), b = trace_host(other.view(), r);
    hits += a.prim != kNoHit;
    if (a.prim == b.prim && a.prim != kNoHit && a.t != b.t) ++t_differs;
    // Segments to 0.999 of the way to the closest hit (unoccluded) and to the far side
    // of it (occluded), as a shadow ray's t_max = 1 against its target.
    if (a.prim != kNoHit) {
      for (float f : {0.999f, 1.001f}) {
        const Vec3f d = r.d * (a.t * f);
        float tb = 0, to = 0;
        const bool ob = traverse<true>(binary.view(), r.o, d, 1.0f, tb) != kNoHit;
        const bool oo = traverse<true>(other.view(), r.o, d, 1.0f, to) != kNoHit;
        if (ob == oo) continue;
        // An edge ray's segment blocked or not at the aimed-at point itself (t = 1 of the
        // ray): the rim of an open edge (the light's), hit or missed by rounding, which the
        // rectangles' test (rects) rounds differently from the triangle test.
        if (set == &edges && std::fabs((ob ? tb : to) * a.t * f - 1.0f) < 1e-2f) ++occlusion_at_target_edge;
        else ++occlusion_differs;
      }
    }
  }
  std::printf("[ INFO     ] %s %s vs binary: %zu rays, %zu hits; random: %zu other triangles (%zu not ties); edges: "
              "%zu other triangles (%zu not ties, %zu at the aimed-at edge); %zu t differ, %zu occlusion answers "
              "differ (%zu more at the aimed-at edge)\n",
              label.c_str(), to_string(layout), rays, hits, on_random.prim_mismatch,
              on_random.prim_mismatch_not_tie, on_edges.prim_mismatch, on_edges.prim_mismatch_not_tie,
              on_edges.at_target_edge, t_differs, occlusion_differs, occlusion_at_target_edge);
  EXPECT_GT(hits, rays / 2) << label;
  for (const Agreement* a : {&on_random, &on_edges}) {
    EXPECT_EQ(a->hit_miss_mismatch, 0u) << a->first_problem;
    EXPECT_EQ(a->prim_mismatch_not_tie, 0u) << a->first_problem;
    EXPECT_EQ(a->t_mismatch, 0u) << a->first_problem;
  }
  EXPECT_EQ(t_differs, 0u) << label;
  EXPECT_EQ(occlusion_differs, 0u) << label;
}

class LayoutsAgree : public ::testing::TestWithParam<SceneCase> {};

TEST_P(LayoutsAgree, SameHitsAsTheBinaryBvh) {
  bool ok;
  const Scene scene = load_or_skip(GetParam().name, ok);
  if (!ok) GTEST_SKIP() << "scene " << GetParam().name << " is not built in yet";
  expect_same_hits_as_binary(scene, GetParam().layout, GetParam().name);
}

// The quantised boxes at the extremes of scale: a scene ten thousand times smaller and
// larger than the box's metres (the boxes' pad and steps follow the scene's size).
TEST(LayoutsAgreeScaled, TinyAndHugeScenes) {
  for (float scale : {1e-4f, 1e4f}) {
    Scene scene = load_scene("paper-cornell-ico:2");
    for (Vec3f& p : scene.positions) p = p * scale + Vec3f{0.5f, -0.25f, 0.125f} * scale;
    scene.finalize();
    for (GpuBvhLayout l : {GpuBvhLayout::Wide8, GpuBvhLayout::Wide4, GpuBvhLayout::Brute, GpuBvhLayout::Leaves})
      expect_same_hits_as_binary(scene, l, "paper-cornell-ico:2 x " + std::to_string(scale));
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, LayoutsAgree,
                         ::testing::Values(SceneCase{"paper-cornell", true, GpuBvhLayout::Wide8},
                                           SceneCase{"paper-cornell", true, GpuBvhLayout::Wide4},
                                           SceneCase{"paper-cornell", true, GpuBvhLayout::Brute},
                                           SceneCase{"paper-cornell-ico:0", true, GpuBvhLayout::Brute},
                                           SceneCase{"paper-cornell-ico:1", true, GpuBvhLayout::Brute},
                                           SceneCase{"paper-cornell", true, GpuBvhLayout::Leaves},
                                           SceneCase{"paper-cornell-ico:1", true, GpuBvhLayout::Leaves},
                                           SceneCase{"paper-cornell-ico:0", true, GpuBvhLayout::Leaves},
                                           SceneCase{"cornell-box", false, GpuBvhLayout::Leaves},
                                           SceneCase{"paper-cornell-ico:4", true, GpuBvhLayout::Wide8},
                                           SceneCase{"paper-cornell-ico:4", true, GpuBvhLayout::Wide4},
                                           SceneCase{"cornell-box", false, GpuBvhLayout::Wide8},
                                           SceneCase{"paper-cornell", true, GpuBvhLayout::Rects},
                                           SceneCase{"paper-cornell-ico:0", true, GpuBvhLayout::RectsBinary},
                                           SceneCase{"paper-cornell-ico:4", true, GpuBvhLayout::RectsBinary}),
                         case_name);

// The rectangles at the extremes of scale, and moved off the origin: paper-cornell ten
// thousand times smaller and larger.
TEST(LayoutsAgreeScaled, RectsTinyAndHugeScenes) {
  for (float scale : {1e-4f, 1e4f}) {
    Scene scene = load_scene("paper-cornell");
    for (Vec3f& p : scene.positions) p = p * scale + Vec3f{0.5f, -0.25f, 0.125f} * scale;
    scene.finalize();
    expect_same_hits_as_binary(scene, GpuBvhLayout::Rects, "paper-cornell x " + std::to_string(scale));
    Scene ico = load_scene("paper-cornell-ico:2");
    for (Vec3f& p : ico.positions) p = p * scale + Vec3f{0.5f, -0.25f, 0.125f} * scale;
    ico.finalize();
    expect_same_hits_as_binary(ico, GpuBvhLayout::RectsBinary, "paper-cornell-ico:2 x " + std::to_string(scale));
  }
}

// auto's rule (bvh_layout.h): rects where every triangle pairs into an axis-aligned
// rectangle, else leaves; asked for by name on another scene, a clear error.
TEST(RectsLayout, AutoPicksRectsWhereEveryTriangleIsHalfARectangle) {
  const Scene box = load_scene("paper-cornell");
  EXPECT_EQ(build_scene_bvh(box, GpuBvhOptions{}).layout, GpuBvhLayout::Rects);
  const SceneBvhHost r = build_scene_bvh(box, GpuBvhOptions{});
  EXPECT_EQ(r.rects.size(), 7u);
  EXPECT_EQ(r.nodes(), 7u);
  EXPECT_EQ(r.view().kind, TraversalKind::Rects);
  const Scene ico = load_scene("paper-cornell-ico:0");
  EXPECT_EQ(build_scene_bvh(ico, GpuBvhOptions{}).layout, GpuBvhLayout::Binary);  // 34 triangles: past the leaves' 32
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Rects;
  try {
    build_scene_bvh(ico, o);
    ADD_FAILURE() << "rects accepted a scene with an icosphere";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not half of an axis-aligned rectangle"), std::string::npos) << e.what();
  }
  EXPECT_EQ(parse_gpu_bvh_layout("rects"), GpuBvhLayout::Rects);
  // Two triangles that share a diagonal but are not a rectangle's halves (a kite).
  Scene kite = box;
  kite.positions[11] = kite.positions[11] + Vec3f{0.5f, 0.0f, 0.0f};
  std::vector<AxisRect> rects;
  RectGroups groups;
  std::string why;
  EXPECT_FALSE(build_axis_rects(kite, rects, groups, &why));
  EXPECT_NE(why.find("triangle 12"), std::string::npos) << why;
  EXPECT_EQ(build_scene_bvh(kite, GpuBvhOptions{}).layout, GpuBvhLayout::Leaves);
}

// Asked for by name, rects refuses a scene past kLeavesMaxTriangles even where every
// triangle pairs (it tests every rectangle for every ray; before, such a scene was
// accepted). Its other refusals: BvhLayout.LeavesAndRectsRefuseInstancesAndLargeScenes.
TEST(RectsLayout, RefusesLargeScenesWhoseTrianglesAllPair) {
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Rects;
  Scene strips = load_scene("paper-cornell");  // its materials; a row of unit squares in z = 0
  strips.positions.clear();
  strips.triangles.clear();
  const uint32_t squares = kLeavesMaxTriangles / 2 + 1;
  for (uint32_t i = 0; i <= squares; ++i) {
    strips.positions.push_back({float(i), 0.0f, 0.0f});
    strips.positions.push_back({float(i), 1.0f, 0.0f});
  }
  for (uint32_t i = 0; i < squares; ++i) {
    strips.triangles.push_back({{2 * i, 2 * i + 2, 2 * i + 3}});
    strips.triangles.push_back({{2 * i, 2 * i + 3, 2 * i + 1}});
  }
  strips.material_ids.assign(strips.triangles.size(), 0);
  ASSERT_GT(strips.triangles.size(), size_t(kLeavesMaxTriangles));
  std::vector<AxisRect> rects;
  RectGroups groups;
  ASSERT_TRUE(build_axis_rects(strips, rects, groups));  // every triangle pairs
  try {
    build_scene_bvh(strips, o);
    ADD_FAILURE() << "rects accepted " << strips.triangles.size() << " triangles";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("GPU BVH layout rects"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("takes at most"), std::string::npos) << e.what();
  }
}

// The rectangles' least t is ray_t_min's, bit for bit; a hit's triangle is the half of
// its rectangle the hit point lies in, and at a corner of three walls or an edge of two a
// ray aimed exactly at it from inside hits one of them (the plane t's are compared, a
// total order).
TEST(RectsLayout, CornersAndEdgesOfTheBoxAreClosed) {
  const Scene box = load_scene("paper-cornell");
  const SceneBvhHost r = build_scene_bvh(box, GpuBvhOptions{});
  const BvhView v = r.view();
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-9.5f, 9.5f), z(-9.5f, 21.5f);
  const float xs[2] = {-10.0f, 10.0f}, ys[2] = {-10.0f, 10.0f}, zs[2] = {-10.0f, 22.0f};
  int misses = 0, tested = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f o{u(rng), u(rng), z(rng)};
    // A corner, or a point of an edge of two walls.
    Vec3f target{xs[i & 1], ys[(i >> 1) & 1], zs[(i >> 2) & 1]};
    const int free_axis = (i >> 3) % 4;  // 3: the corner itself
    if (free_axis == 0) target.x = u(rng);
    if (free_axis == 1) target.y = u(rng);
    if (free_axis == 2) target.z = z(rng);
    const Vec3f d = target - o;
    float t = 0;
    const uint32_t prim = traverse<false>(v, o, d, 2.0f, t);
    ++tested;
    if (prim == kNoHit) ++misses;
    else if (prim < 12) EXPECT_NEAR(t, 1.0f, 1e-5f) << "ray " << i;  // 12, 13: the light hangs below the ceiling
    EXPECT_EQ(0x1p-21f * max_component(vabs(o)) * pmin(pmin(std::fabs(detail::safe_inverse(d.x)),
                                                            std::fabs(detail::safe_inverse(d.y))),
                                                       std::fabs(detail::safe_inverse(d.z))),
              ray_t_min(o, d));
  }
  EXPECT_EQ(misses, 0) << "of " << tested << " rays at the box's corners and edges";
  // The light's two halves: points either side of its diagonal, from below.
  for (const Vec3f& target : {Vec3f{-4.0f, 9.9f, -3.0f}, Vec3f{4.0f, 9.9f, -7.0f}}) {
    const Vec3f o{0.0f, 0.0f, 0.0f};
    float t = 0;
    const uint32_t prim = traverse<false>(v, o, target - o, 2.0f, t);
    const SceneBvhHost leaves = [&] {
      GpuBvhOptions o2;
      o2.layout = GpuBvhLayout::Leaves;
      return build_scene_bvh(box, o2);
    }();
    float t2 = 0;
    EXPECT_EQ(prim, traverse<false>(leaves.view(), o, target - o, 2.0f, t2));
    EXPECT_EQ(t, t2);
    EXPECT_GE(prim, 12u);
  }
}

// --no-watertight (Moeller-Trumbore, the accuracy study's triangle test) on a rects scene
// traces the leaves the layout keeps: the leaves layout's answers, not the rectangles'.
TEST(RectsLayout, MoellerTrumboreTracesTheLeaves) {
  const Scene box = load_scene("paper-cornell");
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Leaves;
  const SceneBvhHost rects = build_scene_bvh(box, GpuBvhOptions{}), leaves = build_scene_bvh(box, o);
  ASSERT_EQ(rects.layout, GpuBvhLayout::Rects);
  const Vec3f ext = box.bounds_max - box.bounds_min;
  const auto rays = test::random_rays(box.bounds_min + ext * 0.02f, box.bounds_max - ext * 0.02f, 5000, 29);
  size_t differ = 0;
  for (const Ray3& r : rays) {
    float ta = 0, tb = 0;
    const uint32_t a = traverse<false, false>(rects.view(), r.o, r.d, r.t_max, ta);
    const uint32_t b = traverse<false, false>(leaves.view(), r.o, r.d, r.t_max, tb);
    float tc = 0, td = 0;
    const uint32_t c = traverse<false, false, int(TraversalKind::Rects)>(rects.view(), r.o, r.d, r.t_max, tc);
    const uint32_t d = traverse<false, false, int(TraversalKind::Leaves)>(leaves.view(), r.o, r.d, r.t_max, td);
    differ += a != b || ta != tb || c != d || tc != td || a != c || ta != tc;
  }
  EXPECT_EQ(differ, 0u);
}

// rects-binary (rects_binary.h), by name: the rectangles are a room's walls and light; the
// BVH holds the rest under their scene ids, and the rectangles' triangles follow them for
// Moeller-Trumbore. auto does not take it (measured: bvh_layout.h).
TEST(RectsBinaryLayout, TheWallsOfARoom) {
  GpuBvhOptions by_name;
  by_name.layout = GpuBvhLayout::RectsBinary;
  for (const char* name : {"paper-cornell-ico:0", "paper-cornell-ico:3"}) {
    const Scene s = load_scene(name);
    EXPECT_EQ(build_scene_bvh(s, GpuBvhOptions{}).layout, GpuBvhLayout::Binary) << name;
    const SceneBvhHost b = build_scene_bvh(s, by_name);
    ASSERT_EQ(b.layout, GpuBvhLayout::RectsBinary) << name;
    EXPECT_EQ(b.rects.size(), 7u) << name;  // 6 walls and the light
    EXPECT_EQ(b.rect_tris, 14u) << name;
    const BvhView v = b.view();
    EXPECT_EQ(v.kind, TraversalKind::RectsBinary);
    EXPECT_EQ(v.rects_binary.rest.num_tris, s.triangles.size() - 14) << name;
    EXPECT_EQ(v.rects_binary.num_rect_tris, 14u);
    std::vector<char> seen(s.triangles.size(), 0);
    for (uint32_t i = 0; i < v.rects_binary.rest.num_tris; ++i) seen[v.rects_binary.rest.tris[i].prim] += 1;
    for (uint32_t i = 0; i < 14; ++i) seen[v.rects_binary.rect_tris[i].prim] += 10;
    for (size_t i = 0; i < s.triangles.size(); ++i)
      EXPECT_EQ(int(seen[i]), i < 14 ? 10 : 1) << name << ": triangle " << i;  // the box's 14 come first
  }
  EXPECT_EQ(parse_gpu_bvh_layout("rects-binary"), GpuBvhLayout::RectsBinary);
}

// Asked for by name, rects-binary refuses a scene it cannot trace, saying why: one whose
// triangles are all rectangles (rects suits it), one with no rectangle, one with instances.
TEST(RectsBinaryLayout, RefusesWhatItCannotTrace) {
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::RectsBinary;
  const Scene inst = load_scene(std::string(PATHBENCH_SOURCE_DIR) + "/scenes/examples/instancing.json");
  Scene sphere = load_scene("paper-cornell-ico:1");  // the icosphere alone
  sphere.triangles.erase(sphere.triangles.begin(), sphere.triangles.begin() + 14);
  sphere.material_ids.erase(sphere.material_ids.begin(), sphere.material_ids.begin() + 14);
  sphere.finalize();
  for (const auto& [scene, why] : {std::pair{load_scene("paper-cornell"), "rects suits it"},
                                   std::pair{sphere, "no two triangles"},
                                   std::pair{inst, "instances"}}) {
    try {
      build_scene_bvh(scene, o);
      ADD_FAILURE() << "rects-binary accepted " << scene.name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("GPU BVH layout rects-binary"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  }
}

// The largest rectangles, at most the limit asked for; of equal areas the lower ids; the
// cover is their area over the scene box's surface.
TEST(RectsBinaryLayout, KeepsTheLargestRectangles) {
  Scene strips = load_scene("paper-cornell");  // its materials; 20 squares of side 1..20 in z = 0, apart
  strips.positions.clear();
  strips.triangles.clear();
  float x = 0;
  for (uint32_t i = 0; i < 20; ++i) {
    const float side = float(20 - i);
    const uint32_t b = uint32_t(strips.positions.size());
    for (const Vec3f& p : {Vec3f{x, 0, 0}, Vec3f{x + side, 0, 0}, Vec3f{x, side, 0}, Vec3f{x + side, side, 0}})
      strips.positions.push_back(p);
    strips.triangles.push_back({{b, b + 1, b + 3}});
    strips.triangles.push_back({{b, b + 3, b + 2}});
    x += side + 1;
  }
  strips.material_ids.assign(strips.triangles.size(), 0);
  strips.finalize();
  std::vector<AxisRect> rects;
  RectGroups groups;
  std::vector<char> in_rect;
  const double cover = largest_axis_rects(strips, 16, rects, groups, in_rect);
  ASSERT_EQ(rects.size(), 16u);
  EXPECT_EQ(groups.end[0], 0u);
  EXPECT_EQ(groups.end[1], 0u);
  EXPECT_EQ(groups.end[2], 16u);
  for (uint32_t i = 0; i < 40; ++i) EXPECT_EQ(in_rect[i] != 0, i < 32) << "triangle " << i;
  double area = 0;
  for (uint32_t i = 0; i < 16; ++i) {
    EXPECT_EQ(rects[i].key, 2 * i);
    area += double(20 - i) * double(20 - i);
  }
  const Vec3f e = strips.bounds_max - strips.bounds_min;  // flat: the surface is twice the face
  EXPECT_NEAR(cover, area / (2.0 * double(e.x) * double(e.y)), 1e-9);
}

// --no-watertight (Moeller-Trumbore) on rects-binary tests the rectangles' triangles with
// that test, so its answers are the binary BVH's with Moeller-Trumbore over every triangle.
TEST(RectsBinaryLayout, MoellerTrumboreTestsTheWallsTriangles) {
  const Scene s = load_scene("paper-cornell-ico:2");
  GpuBvhOptions o, by_name;
  o.layout = GpuBvhLayout::Binary;
  by_name.layout = GpuBvhLayout::RectsBinary;
  const SceneBvhHost walls = build_scene_bvh(s, by_name), binary = build_scene_bvh(s, o);
  ASSERT_EQ(walls.layout, GpuBvhLayout::RectsBinary);
  const Vec3f ext = s.bounds_max - s.bounds_min;
  const auto rays = test::random_rays(s.bounds_min + ext * 0.02f, s.bounds_max - ext * 0.02f, 5000, 31);
  size_t differ = 0, occlusion_differs = 0;
  for (const Ray3& r : rays) {
    float ta = 0, tb = 0, tc = 0;
    const uint32_t a = traverse<false, false>(walls.view(), r.o, r.d, r.t_max, ta);
    const uint32_t b = traverse<false, false>(binary.view(), r.o, r.d, r.t_max, tb);
    const uint32_t c = traverse<false, false, int(TraversalKind::RectsBinary)>(walls.view(), r.o, r.d, r.t_max, tc);
    differ += a != b || ta != tb || a != c || ta != tc;
    if (b == kNoHit) continue;
    const Vec3f d = r.d * (tb * 0.999f);
    occlusion_differs += (traverse<true, false>(walls.view(), r.o, d, 1.0f, ta) != kNoHit) !=
                         (traverse<true, false>(binary.view(), r.o, d, 1.0f, tb) != kNoHit);
  }
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(occlusion_differs, 0u);
}

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
  for (GpuBvhLayout l :
       {GpuBvhLayout::Binary, GpuBvhLayout::Wide4, GpuBvhLayout::Wide8, GpuBvhLayout::Brute, GpuBvhLayout::Leaves}) {
    GpuBvhOptions o;
    o.layout = l;
    const SceneBvhHost bvh = build_scene_bvh(s, o);
    float t;
    EXPECT_EQ(traverse<false>(bvh.view(), {0, 0, 0}, {0, 0, 1}, 1e30f, t), kNoHit) << to_string(l);
    EXPECT_FALSE(occluded(bvh.view(), {0, 0, 0}, {1, 1, 1}, 1.0f)) << to_string(l);
  }
}

// The layout choice: auto takes brute force up to the threshold, else the wide BVH; the
// environment's names are checked, and a bad one is an InputError naming the variable.
TEST(BvhLayout, AutoAndNames) {
  // The default, as measured on an H100: the leaves alone for tiny scenes without instances,
  // else the binary BVH; no brute force.
  EXPECT_EQ(resolve_layout(GpuBvhOptions{}, 14), GpuBvhLayout::Leaves);
  EXPECT_EQ(resolve_layout(GpuBvhOptions{}, kLeavesAutoMaxTriangles), GpuBvhLayout::Leaves);
  EXPECT_EQ(resolve_layout(GpuBvhOptions{}, kLeavesAutoMaxTriangles + 1), GpuBvhLayout::Binary);
  EXPECT_EQ(resolve_layout(GpuBvhOptions{}, 14, 2), GpuBvhLayout::Binary);  // instances: ties need the binary rule
  EXPECT_EQ(resolve_layout(GpuBvhOptions{}, 1310734), GpuBvhLayout::Binary);
  GpuBvhOptions o;
  o.brute_max_triangles = 20;
  EXPECT_EQ(resolve_layout(o, 20), GpuBvhLayout::Brute);
  EXPECT_EQ(resolve_layout(o, 21), GpuBvhLayout::Leaves);
  EXPECT_EQ(resolve_layout(o, 100), kAutoLayout);
  o.layout = GpuBvhLayout::Binary;
  EXPECT_EQ(resolve_layout(o, 5), GpuBvhLayout::Binary);
  for (GpuBvhLayout l : {GpuBvhLayout::Auto, GpuBvhLayout::Binary, GpuBvhLayout::Wide4, GpuBvhLayout::Wide8,
                         GpuBvhLayout::Brute, GpuBvhLayout::Leaves, GpuBvhLayout::Rects, GpuBvhLayout::RectsBinary})
    EXPECT_EQ(parse_gpu_bvh_layout(to_string(l)), l);
  try {
    parse_gpu_bvh_layout("wide16");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("PATHBENCH_GPU_BVH"), std::string::npos) << e.what();
  }
  ::setenv("PATHBENCH_GPU_BRUTE_MAX_TRIS", "12x", 1);
  EXPECT_THROW(GpuBvhOptions::from_env(), InputError);
  ::setenv("PATHBENCH_GPU_BRUTE_MAX_TRIS", "7", 1);
  ::setenv("PATHBENCH_GPU_BVH", "wide4", 1);
  const GpuBvhOptions e = GpuBvhOptions::from_env();
  EXPECT_EQ(e.brute_max_triangles, 7u);
  EXPECT_EQ(e.layout, GpuBvhLayout::Wide4);
  ::unsetenv("PATHBENCH_GPU_BRUTE_MAX_TRIS");
  ::unsetenv("PATHBENCH_GPU_BVH");
}

// The leaves and rects layouts refuse what they cannot serve, naming the layout and the
// reason: a scene with instances (its ties) and one past kLeavesMaxTriangles.
TEST(BvhLayout, LeavesAndRectsRefuseInstancesAndLargeScenes) {
  const Scene big = load_scene("paper-cornell-ico:7");  // 327,694 triangles
  ASSERT_GT(big.triangles.size(), size_t(kLeavesMaxTriangles));
  const Scene inst = load_scene(std::string(PATHBENCH_SOURCE_DIR) + "/scenes/examples/instancing.json");
  ASSERT_FALSE(inst.instances.empty());
  GpuBvhOptions o;
  for (const GpuBvhLayout layout : {GpuBvhLayout::Leaves, GpuBvhLayout::Rects}) {
    o.layout = layout;
    const std::string name = std::string("GPU BVH layout ") + to_string(layout);
    for (const auto& [scene, why] : {std::pair{&big, "triangles; it tests every"}, std::pair{&inst, "instances"}}) {
      try {
        build_scene_bvh(*scene, o);
        ADD_FAILURE() << name << ": no InputError for " << scene->name;
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
      }
    }
  }
  o.layout = GpuBvhLayout::Auto;  // auto never picks either there
  EXPECT_EQ(build_scene_bvh(inst, o).layout, GpuBvhLayout::Binary);
}

// The wide traversal's short stack (registers over a local-memory array) is a plain
// stack: pushes and pops past its register part come back in LIFO order, to the full depth.
template <int N>
void check_short_stack() {
  detail::WideShortStack<N> s;
  detail::WideGroup spill[kWideStackSize - N];
  std::vector<detail::WideGroup> model;
  std::mt19937 rng(3);
  size_t deepest = 0;
  for (int i = 0; i < 20000; ++i) {
    const bool push = model.empty() || (model.size() < size_t(kWideStackSize) && rng() % 100 < 55);
    if (push) {
      const detail::WideGroup g{uint32_t(rng()), uint32_t(rng())};
      s.push(g, spill);
      model.push_back(g);
      deepest = std::max(deepest, model.size());
    } else {
      const detail::WideGroup g = s.pop(spill);
      ASSERT_EQ(g.base, model.back().base) << "N " << N << ", step " << i;
      ASSERT_EQ(g.hits, model.back().hits) << "N " << N << ", step " << i;
      model.pop_back();
    }
    ASSERT_EQ(s.empty(), model.empty());
  }
  EXPECT_GT(deepest, size_t(N) + 8);  // the local-memory part was used
}

TEST(WideBvh, ShortStackIsAPlainStack) {
  check_short_stack<0>();  // the default (kWideShortStack)
  check_short_stack<4>();  // 4 groups in registers over the local array
}

// The quantised child boxes hold the children they stand for: every triangle of a
// wide leaf lies inside its slot's box, decoded exactly (in double).
TEST(WideBvh, QuantisedBoxesHoldTheirTriangles) {
  const Scene scene = load_scene("paper-cornell-ico:3");
  GpuBvhOptions o;
  o.layout = GpuBvhLayout::Wide8;
  const SceneBvhHost b = build_scene_bvh(scene, o);
  size_t checked = 0, children = 0;
  for (const WideNode& n : b.wide.nodes) {
    for (uint32_t s = 0; s < 8; ++s) {
      if (n.meta[s] == 0) continue;
      ++children;
      if ((n.imask >> s) & 1u) continue;
      const uint32_t count = n.meta[s] >> 5 == 7 ? 3 : n.meta[s] >> 5 == 3 ? 2 : 1;
      for (uint32_t k = 0; k < count; ++k) {
        const BvhTriangle& t = b.wide.tris[n.tri_base + (n.meta[s] & 31u) + k];
        for (const float* v : {t.v0, t.v1, t.v2})
          for (int a = 0; a < 3; ++a) {
            const double step = std::ldexp(1.0, int(n.e[a]) - 127);
            EXPECT_LE(double(n.p[a]) + n.qlo[a][s] * step, double(v[a]));
            EXPECT_GE(double(n.p[a]) + n.qhi[a][s] * step, double(v[a]));
          }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, scene.triangles.size());
  std::printf("[ INFO     ] wide8 on %zu triangles: %zu nodes, %.2f children a node\n", scene.triangles.size(),
              b.wide.nodes.size(), double(children) / b.wide.nodes.size());
}

// The builder's environment overrides (BvhBuildOptions::with_env, for measuring builds):
// taken where valid, refused with the variable's name where not; a high-quality build with
// small leaves still traces as the binary BVH does.
TEST(BvhBuildOptions, EnvironmentOverrides) {
  const auto with = [](const char* var, const char* value) {
    setenv(var, value, 1);
    BvhBuildOptions o;
    try {
      o = BvhBuildOptions{}.with_env();
    } catch (...) {
      unsetenv(var);
      throw;
    }
    unsetenv(var);
    return o;
  };
  EXPECT_EQ(with("PATHBENCH_GPU_BVH_LEAF_SIZE", "8").max_leaf_size, 8u);
  EXPECT_TRUE(with("PATHBENCH_GPU_BVH_QUALITY", "high").high_quality);
  EXPECT_FLOAT_EQ(with("PATHBENCH_GPU_BVH_TRAVERSAL_COST", "2.5").traversal_cost, 2.5f);
  EXPECT_FLOAT_EQ(with("PATHBENCH_GPU_BVH_INTERSECTION_COST", "0.5").intersection_cost, 0.5f);
  EXPECT_EQ(with("PATHBENCH_GPU_BVH_OPTIMIZE", "0").optimize_passes, 0u);
  EXPECT_EQ(with("PATHBENCH_GPU_BVH_OPTIMIZE", "8").optimize_passes, 8u);
  for (const auto& [var, bad] : {std::pair{"PATHBENCH_GPU_BVH_LEAF_SIZE", "17"}, {"PATHBENCH_GPU_BVH_LEAF_SIZE", "2.5"},
                                 {"PATHBENCH_GPU_BVH_LEAF_SIZE", "four"}, {"PATHBENCH_GPU_BVH_QUALITY", "best"},
                                 {"PATHBENCH_GPU_BVH_TRAVERSAL_COST", "0"}, {"PATHBENCH_GPU_BVH_OPTIMIZE", "9"},
                                 {"PATHBENCH_GPU_BVH_OPTIMIZE", "-1"}, {"PATHBENCH_GPU_BVH_OPTIMIZE", "1.5"}}) {
    try {
      with(var, bad);
      ADD_FAILURE() << var << "=" << bad << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(var), std::string::npos) << e.what();
    }
  }
  setenv("PATHBENCH_GPU_BVH_QUALITY", "high", 1);
  setenv("PATHBENCH_GPU_BVH_LEAF_SIZE", "2", 1);
  const Scene scene = load_scene("paper-cornell-ico:3");
  const SceneBvhHost high = build_scene_bvh(scene, GpuBvhOptions{});
  unsetenv("PATHBENCH_GPU_BVH_QUALITY");
  unsetenv("PATHBENCH_GPU_BVH_LEAF_SIZE");
  const SceneBvhHost medium = build_scene_bvh(scene, GpuBvhOptions{});
  EXPECT_NE(high.binary.nodes.size(), medium.binary.nodes.size());
  const Vec3f ext = scene.bounds_max - scene.bounds_min;
  const auto rays = test::random_rays(scene.bounds_min + ext * 0.02f, scene.bounds_max - ext * 0.02f, 20000, 29);
  size_t differ = 0;
  for (const Ray3& r : rays) {
    const Hit a = trace_host(high.view(), r), b = trace_host(medium.view(), r);
    differ += a.prim != b.prim || a.t != b.t;
  }
  EXPECT_EQ(differ, 0u);
}

// Spatial splits (Embree HIGH) clip a reference's bounds at the split plane; the flattened
// leaves must keep those bounds, not their whole triangles' boxes, or a split only duplicates
// references. Before the leaves kept them (2026-11-27), HIGH's SAH on cornell-box:spheres was
// 23.45 against MEDIUM's 19.03 (bunny-armadillo 41.5 against 19.9); with them 18.85.
TEST(BvhBuildOptions, SpatialSplitsKeepTheirClippedBounds) {
  const Scene scene = load_scene("cornell-box:spheres");
  BvhBuildOptions medium, high;
  high.high_quality = true;
  const BvhHost m = build_bvh(scene, medium), h = build_bvh(scene, high);
  std::printf("[ INFO     ] cornell-box:spheres SAH medium %.3f (%zu references), high %.3f (%zu references)\n",
              m.sah_cost, m.tris.size(), h.sah_cost, h.tris.size());
  EXPECT_GT(h.tris.size(), m.tris.size());  // some triangles were split
  EXPECT_LT(h.sah_cost, m.sah_cost * 1.02);
}

}  // namespace
}  // namespace pb::bvh
