// The CPU tracer's two Embree layouts (EmbreeLayout, settings.h): triangles paired into
// quads across shared edges (cpu/triangle_pairs.h) must be exactly the scene's
// triangles, hits on them must map back to the triangle a triangle-layout scene finds,
// and the automatic choice (cpu/embree_layout.h) must follow its own measurement and be
// remembered. Watertightness of both layouts: test_stability.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "pathbench/scene_io/scene_library.h"
#include "pathbench/cpu/embree_layout.h"
#include "pathbench/cpu/embree_scene.h"
#include "pathbench/cpu/triangle_pairs.h"

namespace pb {
namespace {

std::set<uint32_t> vertex_set(std::initializer_list<uint32_t> v) { return std::set<uint32_t>(v); }

// (a, b, c) is (x, y, z) or one of its rotations: the same triangle, same winding.
bool same_rotation(const std::array<uint32_t, 3>& a, const Triangle& t) {
  for (int r = 0; r < 3; ++r)
    if (a[0] == t.v[r] && a[1] == t.v[(r + 1) % 3] && a[2] == t.v[(r + 2) % 3]) return true;
  return false;
}

// Every quad is its two triangles: Embree's first half (v0, v1, v3) is the first one with
// its winding, the second half (v2, v3, v1) has the second one's vertices.
void expect_quads_are_the_triangles(const Scene& s, const cpu::TrianglePairs& p) {
  ASSERT_EQ(p.triangle.size(), 2 * p.quads.size());
  std::vector<int> seen(s.triangles.size(), 0);
  size_t paired = 0;
  for (size_t q = 0; q < p.quads.size(); ++q) {
    const auto& v = p.quads[q];
    const uint32_t first = p.triangle[2 * q], second = p.triangle[2 * q + 1];
    EXPECT_TRUE(same_rotation({v[0], v[1], v[3]}, s.triangles[first])) << "quad " << q;
    ++seen[first];
    if (second == first) {
      EXPECT_EQ(v[3], v[2]) << "quad " << q << ": a lone triangle is (a, b, c, c)";
    } else {
      const Triangle& t = s.triangles[second];
      EXPECT_EQ(vertex_set({v[2], v[3], v[1]}), vertex_set({t.v[0], t.v[1], t.v[2]})) << "quad " << q;
      ++seen[second];
      paired += 2;
    }
  }
  EXPECT_EQ(paired, p.paired);
  for (size_t t = 0; t < seen.size(); ++t) EXPECT_EQ(seen[t], 1) << "triangle " << t << " in " << seen[t] << " quads";
}

TEST(TrianglePairs, PaperCornellPairsEachWallAndTheLight) {
  const Scene s = make_paper_cornell();
  const cpu::TrianglePairs p = cpu::pair_triangles(s);
  EXPECT_EQ(p.paired, s.triangles.size());
  EXPECT_EQ(p.quads.size(), 7u);
  expect_quads_are_the_triangles(s, p);
  // The walls' two halves are listed together (rows of paper-scene.md): each pair is
  // triangles 2k and 2k + 1, the coplanar neighbours, not a neighbour round a corner.
  for (size_t q = 0; q < p.quads.size(); ++q) EXPECT_EQ(p.triangle[2 * q] / 2, p.triangle[2 * q + 1] / 2) << "quad " << q;
}

TEST(TrianglePairs, ClosedMeshesPairUpAndLoneTrianglesStayAlone) {
  const Scene ico = make_paper_cornell_ico(4);
  const cpu::TrianglePairs p = cpu::pair_triangles(ico);
  EXPECT_GE(double(p.paired), 0.9 * double(ico.triangles.size()));
  expect_quads_are_the_triangles(ico, p);

  Scene soup;  // three triangles with no edge in common, one pair across a right angle
  soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}, {0, 0, 9}, {1, 0, 9}, {0, 1, 9}, {0, 0, 10}};
  soup.triangles = {{{0, 1, 2}}, {{3, 4, 5}}, {{6, 7, 8}}, {{6, 7, 9}}};
  const cpu::TrianglePairs q = cpu::pair_triangles(soup);
  EXPECT_EQ(q.paired, 0u) << "the last two meet at 90 degrees: not paired";
  EXPECT_EQ(q.quads.size(), 4u);
  expect_quads_are_the_triangles(soup, q);
}

// Random rays inside paper-cornell and through a tessellated sphere: quads and triangles
// give the same triangle and t, except where a ray meets a shared edge (a tie: then the
// same t, for either triangle).
TEST(EmbreeLayouts, QuadsFindTheTrianglesThatTrianglesFind) {
  for (const Scene& s : {make_paper_cornell(), make_paper_cornell_ico(4)}) {
    const auto tris_scene = cpu::make_embree_scene(s, true, EmbreeLayout::Triangles);
    const auto quads_scene = cpu::make_embree_scene(s, true, EmbreeLayout::Quads);
    const cpu::EmbreeScene &tris = *tris_scene, &quads = *quads_scene;
    ASSERT_EQ(tris.layout(), EmbreeLayout::Triangles);
    ASSERT_EQ(quads.layout(), EmbreeLayout::Quads);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::normal_distribution<float> g(0.0f, 1.0f);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    int same = 0, ties = 0, hits = 0;
    constexpr int kRays = 200000;
    for (int i = 0; i < kRays; ++i) {
      const Vec3f o = s.bounds_min + (s.bounds_max - s.bounds_min) * Vec3f{0.05f + 0.9f * u(rng), 0.05f + 0.9f * u(rng), 0.05f + 0.9f * u(rng)};
      const Vec3f d{g(rng), g(rng), g(rng)};
      RTCRayHit a{}, b{};
      for (RTCRayHit* rh : {&a, &b}) {
        rh->ray.org_x = o.x; rh->ray.org_y = o.y; rh->ray.org_z = o.z;
        rh->ray.dir_x = d.x; rh->ray.dir_y = d.y; rh->ray.dir_z = d.z;
        rh->ray.tfar = std::numeric_limits<float>::infinity();
        rh->ray.mask = ~0u;
        rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect1(tris.handle(), &ctx, &a);
      rtcIntersect1(quads.handle(), &ctx, &b);
      const bool hit_a = a.hit.geomID != RTC_INVALID_GEOMETRY_ID, hit_b = b.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      ASSERT_EQ(hit_a, hit_b) << s.name << " ray " << i;
      if (!hit_a) continue;
      ++hits;
      const uint32_t ta = tris.triangle(a.hit), tb = quads.triangle(b.hit);
      ASSERT_LT(tb, s.triangles.size());
      if (ta == tb) {
        ++same;
        EXPECT_NEAR(a.ray.tfar, b.ray.tfar, 1e-5f * a.ray.tfar) << s.name << " ray " << i;
      } else {
        ++ties;
        EXPECT_NEAR(a.ray.tfar, b.ray.tfar, 1e-4f * a.ray.tfar) << s.name << " ray " << i << ": triangles " << ta << " / " << tb;
      }
    }
    EXPECT_GT(hits, kRays / 2) << s.name;
    EXPECT_LE(ties, hits / 1000) << s.name << ": " << ties << " of " << hits << " hits on another triangle";
  }
}

TEST(EmbreeLayouts, AutoFollowsItsProbeAndIsRemembered) {
  const Scene s = make_paper_cornell();
  const cpu::LayoutChoice a = cpu::choose_embree_layout(s, true), b = cpu::choose_embree_layout(s, true);
  ASSERT_GT(a.triangles_ns, 0.0) << "paper-cornell pairs up completely: both layouts are measured";
  ASSERT_GT(a.quads_ns, 0.0);
  EXPECT_EQ(a.paired, s.triangles.size());
  EXPECT_EQ(a.layout == EmbreeLayout::Quads, a.quads_ns < 0.9 * a.triangles_ns) << a.reason;
  EXPECT_EQ(b.layout, a.layout);  // remembered: the same numbers, not a second measurement
  EXPECT_EQ(b.triangles_ns, a.triangles_ns);
  EXPECT_EQ(b.quads_ns, a.quads_ns);
  const auto automatic = cpu::make_embree_scene(s, true);
  EXPECT_EQ(automatic->layout(), a.layout);

  Scene soup = make_paper_cornell();  // the box plus 20 loose triangles: too few pairs
  for (int k = 0; k < 20; ++k) {
    const auto first = uint32_t(soup.positions.size());
    const float x = -8.0f + 0.8f * float(k);
    soup.positions.insert(soup.positions.end(), {{x, -5, 0}, {x + 0.5f, -5, 0}, {x, -4, 0}});
    soup.triangles.push_back({{first, first + 1, first + 2}});
    soup.material_ids.push_back(soup.material_ids.front());
  }
  soup.finalize();
  const cpu::LayoutChoice c = cpu::choose_embree_layout(soup, true);
  EXPECT_EQ(c.layout, EmbreeLayout::Triangles);
  EXPECT_EQ(c.triangles_ns, 0.0) << "not measured: " << c.reason;
}

// An MPI rank takes rank 0's probed answer (run/ranks_render.cpp, issue 30): remembered, it
// is what every later choice and Auto scene of the process gets, the probe's times and all.
TEST(EmbreeLayouts, RememberedAnswerIsTheProcesssAnswer) {
  Scene s = make_paper_cornell();
  s.positions[0].x += 1e-3f;  // a scene of its own (no other test has remembered it)
  s.finalize();
  ASSERT_TRUE(cpu::remember_embree_layout(s, true, EmbreeLayout::Triangles, 80.5, 79.25,
                                          "quads not measured clearly faster"));
  const cpu::LayoutChoice c = cpu::choose_embree_layout(s, true);
  EXPECT_EQ(c.layout, EmbreeLayout::Triangles);
  EXPECT_EQ(c.triangles_ns, 80.5);
  EXPECT_EQ(c.quads_ns, 79.25);
  EXPECT_STREQ(c.reason, "quads not measured clearly faster");
  EXPECT_EQ(cpu::make_embree_scene(s, true)->layout(), EmbreeLayout::Triangles);
  EXPECT_FALSE(cpu::remember_embree_layout(s, true, EmbreeLayout::Quads, 1, 1, "a reason the probe never gives"));
  EXPECT_EQ(cpu::choose_embree_layout(s, true).layout, EmbreeLayout::Triangles) << "a refused answer is not kept";
}

}  // namespace
}  // namespace pb
