#pragma once
// Walls first (GpuBvhLayout::RectsBinary): a scene whose largest surfaces are a few
// axis-aligned rectangles -- a room's walls, floor, ceiling and light around the meshes
// that matter (the suite's scenes, paper-cornell-ico:L) -- traced as those rectangles
// (axis_plane.h: no triangle test, one L1-resident record each, every lane of a warp
// reading the same one) and a binary BVH over the other triangles (binary_bvh.h).
//
// Why: in a room every ray ends on a wall unless a mesh is nearer, and in one BVH over
// both the walls' boxes span the room, so a ray walks ~10 nodes to reach ~2 triangles
// whichever it hits. Tested first, the rectangles bound the ray: the BVH of the rest then
// culls every box behind the wall the ray hits, and an occlusion query the walls answer
// never enters it. (Host counts, 200,000 random rays from inside paper-cornell-ico:8's
// box: 9.94 nodes and 2.26 triangles a closest hit in one BVH; 7 rectangles, 4.92 nodes
// and 0.41 triangles here.)
//
// The answer is the nearer of the two: the rectangles' least (t, id) hit bounds the
// BVH's t_max, so a triangle of the rest wins only where it is strictly nearer (scenes
// with instances, whose ties need the least (t, id) across both, are not traced this
// way: bvh_layout.cpp refuses them). With --no-watertight (Moeller-Trumbore asked for,
// the accuracy study) the rectangles' own triangles are tested by that test instead
// (`rect_tris`, after the BVH's triangles), so the whole scene keeps its meaning.
// Host+device, as the other traversals.
#include <cstdint>

#include "pathbench/bvh/axis_plane.h"
#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/bvh/brute_force.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"

namespace pb::bvh {

struct RectsBinaryView {
  BinaryBvhView rest;               // the triangles in no rectangle
  const AxisRect* rects = nullptr;  // the rectangles (axis_plane.h), grouped by plane axis
  RectGroups rect_groups{};
  const BvhTriangle* rect_tris = nullptr;  // their triangles (Moeller-Trumbore only)
  uint32_t num_rect_tris = 0;
};

template <bool kAnyHit, bool kWatertight = true>
PB_HD uint32_t traverse_rects_binary(const RectsBinaryView& v, const Vec3f& o, const Vec3f& d, float t_max,
                                     float& t_hit, TraversalStats* stats = nullptr) {
  float t_wall;
  uint32_t wall;
  if constexpr (kWatertight) wall = traverse_rects<kAnyHit>(v.rects, v.rect_groups, o, d, t_max, t_wall, stats);
  else wall = traverse_all<kAnyHit, false>(v.rect_tris, v.num_rect_tris, o, d, t_max, t_wall, stats);
  if (wall == kNoHit) return traverse<kAnyHit, kWatertight, 0>(v.rest, o, d, t_max, t_hit, stats);
  if (kAnyHit) {
    t_hit = t_wall;
    return wall;
  }
  float t_rest;
  const uint32_t rest = traverse<kAnyHit, kWatertight, 0>(v.rest, o, d, t_wall, t_rest, stats);
  if (rest != kNoHit) {
    t_hit = t_rest;
    return rest;
  }
  t_hit = t_wall;
  return wall;
}

}  // namespace pb::bvh
