#pragma once
// Triangles that share an edge, paired into Embree quads. In robust mode Embree tests a
// quad's two triangles in one go, and a closed box made of quads is traced with about a
// third fewer instructions per ray than the same triangles (docs/notes/cpu-log.md).
// The pairing changes no geometry: each quad is exactly two of the scene's triangles,
// with their own vertices; hits are mapped back to the scene's triangle ids.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pathbench/common/scene.h"

namespace pb::cpu {

struct TrianglePairs {
  // Embree quads (v0, v1, v2, v3), which Embree intersects as the triangles (v0, v1, v3)
  // and (v2, v3, v1). A triangle left alone is the quad (a, b, c, c): its second half has
  // no area and is never hit.
  std::vector<std::array<uint32_t, 4>> quads;
  // Two per quad: the scene triangle that is its first half, then its second half (the
  // first again for a triangle left alone).
  std::vector<uint32_t> triangle;
  size_t paired = 0;  // scene triangles that are half of a pair

  // The scene triangle Embree hit: quad `prim` at its hit coordinates (u, v). Embree
  // reports the second half with u + v >= 1 (its (u, v) run over the whole quad).
  uint32_t triangle_of(uint32_t prim, float u, float v) const { return triangle[2 * size_t(prim) + (u + v > 1.0f)]; }
};

// Pairs neighbours across shared edges, greedily, the most nearly coplanar first, never
// across an edge where the two normals are more than 60 degrees apart (a pair's bounding
// box should stay close to its triangles'). Deterministic. Quads are listed in the order
// of their first triangle.
TrianglePairs pair_triangles(const Scene& scene);

}  // namespace pb::cpu
