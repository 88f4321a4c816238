#pragma once
// The binary BVH: built on the host by Embree's BVH builder (bvh_build.cpp), flattened
// into 64-byte nodes that hold both children's boxes (Aila & Laine 2009) over the
// 48-byte triangles of hit_tests.h, stored in leaf order. The traversal below is
// host+device code: the GPU kernels and the host-side tests that check it against
// Embree run the same function.
#include <cstdint>

#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"
#include "pathbench/common/watertight.h"

namespace pb::bvh {

// Two children's boxes, laid out for three 16-byte loads, and their references.
struct alignas(16) BvhNode {
  float x[4];  // c0.lo.x, c0.hi.x, c1.lo.x, c1.hi.x
  float y[4];
  float z[4];
  uint32_t child[2];
  uint32_t pad[2];
};
static_assert(sizeof(BvhNode) == 64, "BvhNode is one 64-byte line");

// What the binary traversal reads: host or device pointers. (The kernels get a BvhView,
// traversal.h: the scene's BVH in whichever layout it was built.)
struct BinaryBvhView {
  const BvhNode* nodes;      // node 0 is the root, always an inner node
  const BvhTriangle* tris;
  uint32_t num_nodes;
  uint32_t num_tris;
  uint32_t exact_ties = 0;   // detail::test_vertices: the least (t, id) wins (scenes with instances)
};

constexpr int kTraversalStackSize = 64;  // the builder limits the depth to fit

namespace detail {

PB_HD void load_node(const BvhNode* nodes, uint32_t i, float (&x)[4], float (&y)[4], float (&z)[4],
                     uint32_t (&child)[2]) {
#if defined(__CUDA_ARCH__)
  const float4* p = reinterpret_cast<const float4*>(nodes + i);
  const float4 a = __ldg(p), b = __ldg(p + 1), c = __ldg(p + 2);
  const uint4 d = __ldg(reinterpret_cast<const uint4*>(p + 3));
  x[0] = a.x; x[1] = a.y; x[2] = a.z; x[3] = a.w;
  y[0] = b.x; y[1] = b.y; y[2] = b.z; y[3] = b.w;
  z[0] = c.x; z[1] = c.y; z[2] = c.z; z[3] = c.w;
  child[0] = d.x; child[1] = d.y;
#else
  const BvhNode& n = nodes[i];
  for (int k = 0; k < 4; ++k) { x[k] = n.x[k]; y[k] = n.y[k]; z[k] = n.z[k]; }
  child[0] = n.child[0]; child[1] = n.child[1];
#endif
}

// Walks a binary BVH (node 0 the root) front to back for the ray (o, d), skipping boxes
// beyond `t`, the best distance so far (read at every node: the leaf test narrows it).
// leaf(first, count) tests a leaf's items and returns true to end the walk (an any-hit
// query's hit); then walk_binary returns true. Shared by the flat traversal below and
// both levels of the two-level one (two_level_bvh.h).
// kFarFirst: where the ray enters both children, the farther first (ties: the second). The
// flat traversal's any-hit (shadow) walks take it: the same answers through other nodes, and
// fewer nodes' time on the GPU. Interleaved against nearer first on an H100, 256x256x800 nee
// (results/nvidia-h100-80gb-hbm3/archive/shadow-order-82da7ca, call3; same films): pixel
// megakernel large-mesh 0.873, bunny-armadillo 0.967, glass-dragon 0.983, paper-cornell-ico:8
// 0.969, ico:5 0.992, cornell-materials 0.992; ico:8 wavefront 0.968, paper-queue 0.937; only
// a tiny mesh lost (ico:1, 94 triangles: 1.007). A host model of this loop on SIMT lanes agrees
// on every scene: per leaf visit a warp pays the most nodes any lane walked to it plus the most
// triangles any lane tests there (that folder's host-model-while-while.txt).
template <bool kFarFirst = false, class Leaf>
PB_HD bool walk_binary(const BvhNode* nodes, const Vec3f& o, const Vec3f& d, const float& t, Leaf&& leaf,
                       TraversalStats* stats) {
  const SlabRay sr = make_slab_ray(o, d);
  uint32_t stack[kTraversalStackSize];
  int sp = 0;
  uint32_t ref = 0;
  for (;;) {
    while (!is_leaf(ref)) {
      float x[4], y[4], z[4];
      uint32_t child[2];
      load_node(nodes, ref, x, y, z, child);
      if (stats) ++stats->nodes;
      float tn[2], tf[2];
      for (int c = 0; c < 2; ++c)
        slab_interval(x[2 * c], x[2 * c + 1], y[2 * c], y[2 * c + 1], z[2 * c], z[2 * c + 1], sr, t, tn[c], tf[c]);
      const bool h0 = tn[0] <= tf[0], h1 = tn[1] <= tf[1];
      if (h0 && h1) {
        const bool swap = (tn[1] < tn[0]) != kFarFirst;
        ref = swap ? child[1] : child[0];
        stack[sp++] = swap ? child[0] : child[1];
      } else if (h0 || h1) {
        ref = h0 ? child[0] : child[1];
      } else {
        if (sp == 0) return false;
        ref = stack[--sp];
      }
    }
    if (leaf(leaf_first(ref), leaf_count(ref))) return true;
    if (sp == 0) return false;
    ref = stack[--sp];
  }
}

}  // namespace detail

// Closest hit (kAnyHit = false) or any hit (true) for ray_t_min < t < t_max (watertight.h:
// a few float ulps of the origin, so that a hit at the ray's own origin counts on no
// device) along the ray's own direction (need not be unit length). Returns the scene
// triangle id, or kNoHit; t_hit receives the distance of a hit. kWatertight = false swaps
// the triangle test for Moeller-Trumbore (the paper's; the accuracy study's comparison;
// it keeps 0 < t).
// kExact: the view's exact_ties read at run time (-1), or known at compile time (0, 1):
// the hot kernels are compiled for one or the other, since a run-time flag keeps the tie
// compare's registers live in every kernel (ptxas, sm_90, k_pixel: 48 -> 60 bytes of
// spill stores, 64 -> 84 of loads) and cost flat scenes ~2 % (docs/notes/gpu-log.md).
// kFarFirst: walk_binary's child order; any-hit walks take the farther child first (the
// renderers' order; tests pass false to compare with the nearer-first walk).
template <bool kAnyHit, bool kWatertight = true, int kExact = -1, bool kFarFirst = kAnyHit>
PB_HD uint32_t traverse(const BinaryBvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                        TraversalStats* stats = nullptr) {
  const bool exact = kExact < 0 ? bvh.exact_ties != 0 : kExact == 1;
  const WatertightRay wr = make_watertight_ray(o, d);
  uint32_t hit = kNoHit, hit_slot = 0;
  float t = t_max;
  const bool stopped = detail::walk_binary<kFarFirst>(
      bvh.nodes, o, d, t,
      [&](uint32_t first, uint32_t count) {
        return detail::test_leaf_triangles<kAnyHit, kWatertight>(bvh.tris, first, count, wr, o, d, t_max, exact, t,
                                                                 hit, hit_slot, stats);
      },
      stats);
  if (kAnyHit && stopped) {
    t_hit = t;
    return hit;
  }
  return detail::finish_closest<kWatertight>(bvh.tris, o, d, t_max, hit, hit_slot, t, t_hit);
}

template <bool kWatertight = true>
PB_HD uint32_t intersect_closest(const BinaryBvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit) {
  return traverse<false, kWatertight>(bvh, o, d, t_max, t_hit);
}
template <bool kWatertight = true>
PB_HD bool occluded(const BinaryBvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max) {
  float t;
  return traverse<true, kWatertight>(bvh, o, d, t_max, t) != kNoHit;
}

}  // namespace pb::bvh
