// Built-in scenes: cornell-box (published Cornell data), paper-cornell-ico:L and
// scaling:N (triangle counts, closed outward-wound spheres), and the registry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"
#include "pathbench/run/run.h"
#include "test_scene_helpers.h"

namespace pb {
namespace {

using scene_test::expect_emitters_face_down;
using scene_test::material_named;
using scene_test::normal_of;

Vec3f centroid_of(const Scene& s, const Triangle& t) {
  return (s.positions[t.v[0]] + s.positions[t.v[1]] + s.positions[t.v[2]]) * (1.0f / 3.0f);
}

// Triangles [first, end) form a closed surface (every edge used once in each
// direction), all at `radius` from `centre`, wound so their normals point out, and
// evenly tessellated (no edge much longer than a triangle of the mean area has).
void expect_closed_outward_sphere(const Scene& s, size_t first, Vec3f centre, float radius) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  size_t inward = 0, off_sphere = 0;
  const float mean_area = 4 * kPi<float> * radius * radius / float(s.triangles.size() - first);
  float longest = 0;
  for (size_t i = first; i < s.triangles.size(); ++i) {
    const Triangle& t = s.triangles[i];
    for (int k = 0; k < 3; ++k) {
      ++directed[{t.v[k], t.v[(k + 1) % 3]}];
      longest = std::max(longest, length(s.positions[t.v[k]] - s.positions[t.v[(k + 1) % 3]]));
    }
    if (dot(normal_of(s, t), centroid_of(s, t) - centre) <= 0) ++inward;
    for (uint32_t v : t.v)
      if (std::fabs(length(s.positions[v] - centre) - radius) > 1e-4f * radius) ++off_sphere;
  }
  EXPECT_EQ(inward, 0u);
  EXPECT_EQ(off_sphere, 0u);
  EXPECT_LT(longest, 5 * std::sqrt(mean_area)) << "slivers: the tessellation is uneven";
  size_t unmatched = 0;
  for (const auto& [edge, count] : directed)
    if (count != 1 || !directed.count({edge.second, edge.first})) ++unmatched;
  EXPECT_EQ(unmatched, 0u) << "the sphere is not a closed, consistently wound surface";
}

TEST(CornellBox, PublishedGeometryCameraAndMaterials) {
  const Scene s = load_scene("cornell-box");
  EXPECT_EQ(s.name, "cornell-box");
  // Floor, back, left, right: 4 quads; ceiling: 4 quads around the light; light: 1;
  // two blocks of 5 quads each.
  EXPECT_EQ(s.triangles.size(), 38u);
  EXPECT_EQ(s.dropped_triangles, 0u);
  EXPECT_FLOAT_EQ(s.bounds_min.x, 0);
  EXPECT_FLOAT_EQ(s.bounds_max.x, 556);
  EXPECT_FLOAT_EQ(s.bounds_max.y, 548.8f);
  EXPECT_FLOAT_EQ(s.bounds_max.z, 559.2f);

  EXPECT_FLOAT_EQ(s.camera.position.x, 278);
  EXPECT_FLOAT_EQ(s.camera.position.y, 273);
  EXPECT_FLOAT_EQ(s.camera.position.z, -800);
  EXPECT_NEAR(s.camera.forward.z, 1, 1e-6);
  EXPECT_NEAR(2 * std::atan(s.camera.tan_half_fov_y) * 180 / kPi<double>, 39.3, 0.05);

  const Material& white = s.materials[material_named(s, "white")];
  const Material& red = s.materials[material_named(s, "red")];
  const Material& green = s.materials[material_named(s, "green")];
  const Material& light = s.materials[material_named(s, "light")];
  EXPECT_FLOAT_EQ(white.albedo.y, 0.75f);
  EXPECT_GT(red.albedo.x, 5 * red.albedo.y);
  EXPECT_GT(green.albedo.y, 2 * green.albedo.x);
  EXPECT_FLOAT_EQ(light.emission.x, 17);
  EXPECT_FLOAT_EQ(light.emission.y, 12);
  EXPECT_FLOAT_EQ(light.emission.z, 4);

  // One-sided emitter facing down, 130 x 105 mm.
  expect_emitters_face_down(s, 2);
  float area = 0;
  for (uint32_t e : s.emitters) {
    const Triangle& t = s.triangles[e];
    area += 0.5f * length(cross(s.positions[t.v[1]] - s.positions[t.v[0]], s.positions[t.v[2]] - s.positions[t.v[0]]));
  }
  EXPECT_NEAR(area, 130 * 105, 1e-2);

  // The red wall is on the image's left (the camera's -right side), green on the right.
  for (size_t i = 0; i < s.triangles.size(); ++i) {
    const float side = dot(centroid_of(s, s.triangles[i]) - s.camera.position, s.camera.right);
    if (s.material_ids[i] == material_named(s, "red")) EXPECT_LT(side, 0);
    if (s.material_ids[i] == material_named(s, "green")) EXPECT_GT(side, 0);
  }
}

TEST(CornellBox, RendersRedOnTheLeftAndGreenOnTheRight) {
  const Scene s = make_cornell_box();
  RenderSettings rs;
  rs.width = rs.height = 24;
  rs.spp = 8;
  rs.progress = false;
  Film film(rs.width, rs.height, false);
  RunReport report;
  run::render(s, rs, film, report);
  const auto img = film.mean();
  auto mean_in_columns = [&](uint32_t x0, uint32_t x1) {
    Vec3d sum{0, 0, 0};
    for (uint32_t y = 0; y < rs.height; ++y)
      for (uint32_t x = x0; x < x1; ++x)
        for (int c = 0; c < 3; ++c) sum[c] += img[(size_t(y) * rs.width + x) * 3 + c];
    return sum;
  };
  const Vec3d left = mean_in_columns(0, 3), right = mean_in_columns(rs.width - 3, rs.width);
  EXPECT_GT(left.x, 2 * left.y) << "left edge should be the red wall";
  EXPECT_GT(right.y, 1.5 * right.x) << "right edge should be the green wall";
  const Vec3d all = mean_in_columns(0, rs.width);
  const double mean = (all.x + all.y + all.z) / (3.0 * rs.width * rs.height);
  EXPECT_GT(mean, 0.05);
  EXPECT_LT(mean, 2.0);
}

TEST(PaperCornellIco, TriangleAndVertexCountsPerLevel) {
  const Scene box = make_paper_cornell();
  for (int level = 0; level <= 3; ++level) {
    const Scene s = load_scene("paper-cornell-ico:" + std::to_string(level));
    const size_t sphere = 20u << (2 * level);
    EXPECT_EQ(s.triangles.size(), box.triangles.size() + sphere) << "level " << level;
    EXPECT_EQ(s.positions.size(), box.positions.size() + sphere / 2 + 2) << "vertices are shared";
    EXPECT_EQ(s.emitters.size(), box.emitters.size());
    EXPECT_EQ(s.name, "paper-cornell-ico:" + std::to_string(level));
  }
}

TEST(PaperCornellIco, SphereIsClosedOutwardAndInPlace) {
  const Scene s = make_paper_cornell_ico(3);
  const size_t first = make_paper_cornell().triangles.size();
  expect_closed_outward_sphere(s, first, {0, -4, -4}, 5.0f);
  const Material& m = s.materials[s.material_ids[first]];
  EXPECT_FLOAT_EQ(m.albedo.x, 0.5f);
  EXPECT_FLOAT_EQ(m.albedo.y, 0.5f);
  EXPECT_FLOAT_EQ(max_component(m.emission), 0.0f);
}

TEST(PaperCornellIco, Level8HasThePublishedCount) {
  const Scene s = make_paper_cornell_ico(8);
  EXPECT_EQ(s.triangles.size() - make_paper_cornell().triangles.size(), 1310720u);
  EXPECT_EQ(s.dropped_triangles, 0u);
}

TEST(Scaling, TriangleCountIsCloseToTheRequest) {
  for (uint64_t n : {20ull, 100ull, 101ull, 1000ull, 4099ull, 12345ull, 100000ull, 1000000ull}) {
    const Scene s = load_scene("scaling:" + std::to_string(n));
    const double got = double(s.triangles.size());
    EXPECT_LE(std::fabs(got - double(n)), 0.03 * double(n)) << "scaling:" << n << " gave " << got;
    EXPECT_EQ(s.dropped_triangles, 0u);
    EXPECT_EQ(s.emitters.size(), 2u) << "the paper's light";
  }
  // Below the box's 14 triangles plus the smallest sphere, the count is the closest possible.
  EXPECT_EQ(load_scene("scaling:10").triangles.size(), 14u);
}

TEST(Scaling, SphereIsClosedOutwardAndEven) {
  for (uint64_t n : {100ull, 5000ull, 20000ull}) {
    SCOPED_TRACE(n);
    expect_closed_outward_sphere(make_scaling(n), make_paper_cornell().triangles.size(), {0, -4, -4}, 5.0f);
  }
}

TEST(Scaling, TenMillion) {
  const Scene s = make_scaling(10000000);
  EXPECT_LE(std::fabs(double(s.triangles.size()) - 1e7), 0.01 * 1e7);
}

TEST(BuiltinScenes, EveryListedSceneLoads) {
  for (const BuiltinSceneInfo& b : builtin_scenes()) {
    EXPECT_FALSE(b.description.empty()) << b.name;
    std::string spec = b.name.substr(0, b.name.find(':'));
    if (spec == "paper-cornell-ico") spec += ":2";
    if (spec == "scaling") spec += ":500";
    const Scene s = load_scene(spec);
    EXPECT_GT(s.triangles.size(), 0u) << spec;
    EXPECT_TRUE(s.features.has_emitters) << spec;
  }
}

}  // namespace
}  // namespace pb
