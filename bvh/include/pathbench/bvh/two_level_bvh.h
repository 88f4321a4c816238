#pragma once
// The GPU's instanced acceleration structure (--instancing, settings.h): a top-level
// binary BVH over the instances' world boxes whose leaves name instances, and one
// bottom-level binary BVH per prototype in the prototype's own coordinates, shared by
// all its instances. The ray goes into an instance's coordinates (its inverse affine)
// only to walk the bottom BVH's boxes; every triangle is tested in world space, on the
// flat scene's triangle (SceneView's positions and triangles, which shading reads anyway),
// with the flat traversal's own test. So the answer is the flat BVH's, bit for bit: the
// closest hit is the least (t, triangle id) of the same per-triangle tests (hit_tests.h:
// detail::closer), whatever order either structure visits them in, provided no box
// culls a triangle the world-space test would hit. The bottom boxes are padded for that
// (two_level_build.cpp: by the measured distance between each instance's flat triangles
// and its transformed prototype, plus the rounding of the ray's transform).
// The triangles no instance covers (walls, lights, instances that lost triangles to
// finalize()) form one more bottom BVH under the identity. Host+device code, as binary_bvh.h.
#include <cstdint>

#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"
#include "pathbench/common/scene.h"

namespace pb::bvh {

struct alignas(16) TwoLevelInstance {
  float inv[12];            // row-major 3x4: traced (world) coordinates -> the prototype's
  uint32_t root;            // its bottom BVH's node 0, in TwoLevelView::bottom_nodes
  uint32_t items;           // its bottom BVH's leaf slot 0, in TwoLevelView::bottom_items
  uint32_t first_triangle;  // a leaf item k names flat triangle first_triangle + k
  uint32_t pad;
};
static_assert(sizeof(TwoLevelInstance) == 64, "TwoLevelInstance is one 64-byte line");

struct TwoLevelView {
  const BvhNode* top_nodes = nullptr;     // node 0 the root; leaf slots index top_items
  const uint32_t* top_items = nullptr;    // leaf slot -> instance
  const TwoLevelInstance* instances = nullptr;
  const BvhNode* bottom_nodes = nullptr;  // each bottom BVH's refs count from its root
  const uint32_t* bottom_items = nullptr; // leaf slot (from the instance's `items`) -> triangle offset
  const Vec3f* positions = nullptr;       // the flat scene, as SceneView has it
  const Triangle* triangles = nullptr;
};

namespace detail {

// The same expressions on host and device (the device library has --fmad=false, the host
// -ffp-contract=off), so HostGpuTracer transforms a ray exactly as the GPU does.
PB_HD Vec3f xform_point(const float (&m)[12], const Vec3f& p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}
PB_HD Vec3f xform_vector(const float (&m)[12], const Vec3f& v) {
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
          m[8] * v.x + m[9] * v.y + m[10] * v.z};
}
PB_HD void load_flat_triangle(const TwoLevelView& v, uint32_t tri, Vec3f& a, Vec3f& b, Vec3f& c) {
  const Triangle t = v.triangles[tri];
  a = v.positions[t.v[0]];
  b = v.positions[t.v[1]];
  c = v.positions[t.v[2]];
}

}  // namespace detail

// As traverse() in binary_bvh.h (same arguments, same answer on the flat scene's triangles).
template <bool kAnyHit, bool kWatertight = true>
PB_HD uint32_t traverse_two_level(const TwoLevelView& v, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                                  TraversalStats* stats = nullptr) {
  const WatertightRay wr = make_watertight_ray(o, d);
  uint32_t hit = kNoHit;
  float t = t_max;
  auto instance_leaf = [&](uint32_t first, uint32_t count) {
    for (uint32_t s = first; s < first + count; ++s) {
      const TwoLevelInstance& in = v.instances[v.top_items[s]];
      const uint32_t* items = v.bottom_items + in.items;
      auto triangle_leaf = [&](uint32_t f, uint32_t n) {
        for (uint32_t k = f; k < f + n; ++k) {
          const uint32_t tri = in.first_triangle + items[k];
          Vec3f a, b, c;
          detail::load_flat_triangle(v, tri, a, b, c);
          if (stats) ++stats->tris;
          if (detail::test_vertices<kWatertight>(a, b, c, tri, wr, o, d, t_max, true, t, hit) && kAnyHit) return true;
        }
        return false;
      };
      const Vec3f lo = detail::xform_point(in.inv, o), ld = detail::xform_vector(in.inv, d);
      if (detail::walk_binary(v.bottom_nodes + in.root, lo, ld, t, triangle_leaf, stats)) return true;
    }
    return false;
  };
  const bool stopped = detail::walk_binary(v.top_nodes, o, d, t, instance_leaf, stats);
  t_hit = t;
  if (kAnyHit && stopped) return hit;
  if (kWatertight && hit != kNoHit) {  // as finish_closest: the winner's t from the plane equation
    Vec3f a, b, c;
    detail::load_flat_triangle(v, hit, a, b, c);
    const float exact = plane_distance(o, d, a, b, c);
    if (exact > 0.0f && exact < t_max) t_hit = exact;
  }
  return hit;
}

}  // namespace pb::bvh
