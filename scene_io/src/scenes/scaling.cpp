// `scaling:N`: the paper's box and light with a tessellated sphere inside, about N
// triangles in all, for scaling studies (how render time and memory grow with the
// triangle count while the light transport stays put).
#include <cmath>
#include <algorithm>

#include "builder.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb {

namespace scenes {

void append_uv_sphere(Scene& s, Vec3f centre, float radius, uint32_t slices, uint32_t rings, uint32_t material) {
  const uint32_t top = add_vertex(s, centre + Vec3f{0, radius, 0});
  const uint32_t first = uint32_t(s.positions.size());
  s.positions.reserve(s.positions.size() + size_t(slices) * rings + 1);
  for (uint32_t i = 1; i <= rings; ++i) {
    const double theta = kPi<double> * i / (rings + 1);
    for (uint32_t j = 0; j < slices; ++j) {
      const double phi = 2 * kPi<double> * j / slices;
      const Vec3d d{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
      s.positions.push_back(centre + Vec3f(d) * radius);
    }
  }
  const uint32_t bottom = add_vertex(s, centre - Vec3f{0, radius, 0});
  auto at = [&](uint32_t ring, uint32_t j) { return first + ring * slices + j % slices; };
  s.triangles.reserve(s.triangles.size() + 2 * size_t(slices) * rings);
  s.material_ids.reserve(s.triangles.size() + 2 * size_t(slices) * rings);
  // Every cell is the loop upper j -> upper j+1 -> lower j+1 -> lower j, which faces out.
  for (uint32_t j = 0; j < slices; ++j) add_triangle(s, top, at(0, j + 1), at(0, j), material);
  for (uint32_t i = 0; i + 1 < rings; ++i)
    for (uint32_t j = 0; j < slices; ++j) add_quad(s, at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j), material);
  for (uint32_t j = 0; j < slices; ++j) add_triangle(s, at(rings - 1, j), at(rings - 1, j + 1), bottom, material);
}

}  // namespace scenes

namespace {

// The sphere's tessellation (slices, rings) whose 2 * slices * rings triangles come
// closest to `target` among those with cells about as wide as tall: slices / rings
// within a factor 2.25 of 2 (so the count is within about sqrt(target) / 2).
struct Tessellation {
  uint32_t slices = 0, rings = 0;
  uint64_t triangles() const { return 2ull * slices * rings; }
};
Tessellation tessellation_for(uint64_t target) {
  const double ideal_rings = std::sqrt(double(target) / 4.0);  // slices = 2 rings
  const uint64_t lo = std::max<uint64_t>(1, uint64_t(ideal_rings / 1.5));
  const uint64_t hi = std::max<uint64_t>(lo, uint64_t(std::ceil(ideal_rings * 1.5)));
  Tessellation best;
  double best_score = 1e300;
  for (uint64_t rings = lo; rings <= hi; ++rings) {
    const uint64_t slices = std::max<uint64_t>(3, (target + rings) / (2 * rings));  // rounded
    const Tessellation t{uint32_t(slices), uint32_t(rings)};
    // Count error first; among equal counts, the better-shaped cells.
    const double aspect = double(slices) / double(rings);
    const double score = std::fabs(double(t.triangles()) - double(target)) + 1e-3 * std::fabs(std::log(aspect / 2));
    if (score < best_score) {
      best_score = score;
      best = t;
    }
  }
  return best;
}

}  // namespace

Scene make_scaling(uint64_t target_triangles) {
  Scene s = make_paper_cornell();
  s.name = "scaling:" + std::to_string(target_triangles);
  const uint64_t box = s.triangles.size();
  // The smallest sphere is a bipyramid of 6 triangles; below 3 the box alone is closer.
  if (target_triangles > box + 3) {
    const Tessellation t = tessellation_for(target_triangles - box);
    const uint32_t grey = scenes::add_material(s, "sphere", {0.5f, 0.5f, 0.5f});
    scenes::append_uv_sphere(s, {0, -4, -4}, 5.0f, t.slices, t.rings, grey);
  }
  s.finalize();
  return s;
}

}  // namespace pb
