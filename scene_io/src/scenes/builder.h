#pragma once
// Small helpers shared by the built-in scenes and the scene-file loaders (private to
// pathbench_common): appending materials, quads and spheres to a Scene.
#include <cstdint>
#include <string>

#include "pathbench/common/scene.h"

namespace pb::scenes {

// Appends a material of any kind and returns its index.
inline uint32_t append_material(Scene& s, std::string name, const Material& m) {
  s.materials.push_back(m);
  s.material_names.push_back(std::move(name));
  return uint32_t(s.materials.size() - 1);
}

// Appends a diffuse material and returns its index.
inline uint32_t add_material(Scene& s, std::string name, Vec3f albedo, Vec3f emission = {0, 0, 0}) {
  return append_material(s, std::move(name), Material{albedo, emission});
}

inline uint32_t add_vertex(Scene& s, Vec3f p) {
  s.positions.push_back(p);
  return uint32_t(s.positions.size() - 1);
}

inline void add_triangle(Scene& s, uint32_t a, uint32_t b, uint32_t c, uint32_t material) {
  s.triangles.push_back({{a, b, c}});
  s.material_ids.push_back(material);
}

// Quad a-b-c-d (existing vertex ids) as the triangles (a,b,c) and (a,c,d): its
// geometric normal is that of cross(b - a, c - a).
inline void add_quad(Scene& s, uint32_t a, uint32_t b, uint32_t c, uint32_t d, uint32_t material) {
  add_triangle(s, a, b, c, material);
  add_triangle(s, a, c, d, material);
}

// Icosphere: the icosahedron subdivided `level` times (20 * 4^level triangles,
// 10 * 4^level + 2 shared vertices), wound so every normal points outwards.
void append_icosphere(Scene& s, Vec3f centre, float radius, int level, uint32_t material);

// Latitude-longitude sphere with `slices` >= 3 meridians and `rings` >= 1 circles of
// latitude between the poles: 2 * slices * rings triangles, shared vertices, outward.
void append_uv_sphere(Scene& s, Vec3f centre, float radius, uint32_t slices, uint32_t rings, uint32_t material);

}  // namespace pb::scenes
