#pragma once
// What the wavefront's batched shading (shade_x8.h) reads and writes, compiled for the
// build's baseline instruction set (shade_x8.h itself is AVX2 code).
#include <cstdint>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

#include "pathbench/common/path.h"

namespace pb::cpu {

constexpr int kShadeLanes = 8;

// One batch: eight paths that hit a triangle, and what shading them asks for next.
struct Shade8 {
  PathState<float>* st[kShadeLanes];
  ShadowQuery<float>* shadow[kShadeLanes];
  uint32_t prim[kShadeLanes];  // hit triangle of each lane
  int lanes;                   // lanes in use; the rest repeat lane 0 and write nothing
  bool wants_shadow[kShadeLanes];
  bool cont[kShadeLanes];      // PathEvent::Continue
};

// Per triangle, everything shading reads of it, as three rows of eight floats so eight
// lanes load it with three 8x8 transposes instead of ~20 scalar loads each:
//   row 0: v0.xyz, e1.xyz, e2.xy     row 1: e2.z, ng.xyz, albedo.xyz, emits
//   row 2: emission.xyz, scatters, 0 x 4
// e1 = v1 - v0, e2 = v2 - v0 and ng = normalize(cross(e1, e2)) are computed exactly as
// surface_hit and path_hit compute them (same float operations, so the same bits);
// `emits` and `scatters` are masks (-1 or 0): emission nonzero, albedo nonzero.
// 96 bytes a triangle: built only for scenes up to kMaxTriangles (the rest shade one
// path at a time).
struct ShadeTable {
  static constexpr uint32_t kRowFloats = 24;
  static constexpr uint32_t kMaxTriangles = 1u << 16;
  std::vector<float> rows;

  static bool fits(const SceneView& s) { return s.num_triangles <= kMaxTriangles; }
  explicit ShadeTable(const SceneView& s) : rows(size_t(s.num_triangles) * kRowFloats, 0.0f) {
    for (uint32_t t = 0; t < s.num_triangles; ++t) {
      const Triangle tri = s.triangles[t];
      const Vec3f v0 = s.positions[tri.v[0]];
      const Vec3f e1 = s.positions[tri.v[1]] - v0;
      const Vec3f e2 = s.positions[tri.v[2]] - v0;
      const Vec3f ng = normalize(cross(e1, e2));
      const Material& m = s.material_of(t);
      const int32_t emits = is_zero(m.emission) ? 0 : -1, scatters = is_zero(m.albedo) ? 0 : -1;
      float* r = &rows[size_t(t) * kRowFloats];
      const float head[16] = {v0.x, v0.y, v0.z, e1.x, e1.y, e1.z, e2.x, e2.y,
                              e2.z, ng.x, ng.y, ng.z, m.albedo.x, m.albedo.y, m.albedo.z, 0.0f};
      std::memcpy(r, head, sizeof head);
      std::memcpy(r + 15, &emits, sizeof emits);
      r[16] = m.emission.x; r[17] = m.emission.y; r[18] = m.emission.z;
      std::memcpy(r + 19, &scatters, sizeof scatters);
    }
  }
  const float* row(uint32_t triangle) const { return &rows[size_t(triangle) * kRowFloats]; }
};

// The batched shading runs for diffuse-only float renders on AVX2 CPUs, in scenes small
// enough for its table: then this returns the table, otherwise null.
template <class T, uint32_t Kinds> std::unique_ptr<ShadeTable> batched_shading_table(const SceneView& s) {
  if constexpr (std::is_same_v<T, float> && Kinds == kDiffuseOnly)
    if (__builtin_cpu_supports("avx2") && ShadeTable::fits(s)) return std::make_unique<ShadeTable>(s);
  return nullptr;
}

}  // namespace pb::cpu
