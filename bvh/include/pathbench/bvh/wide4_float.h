#pragma once
// Experiment (issue 32): the binary BVH collapsed to 4-wide nodes with full-precision child
// boxes (128 bytes: the children's six planes as six float4, their references as a uint4),
// stored two BvhNode slots a node in BvhHost::nodes. Half the dependent node loads of a ray,
// the same boxes (a child's box is the binary node's, padded as built), so the same slab
// tests decide what is hit; children are visited nearest first. Built on the host
// (bvh/src/wide4_float.cpp) and traced instead of the binary layout when the tree is
// compiled with -DPB_BINARY_AS_WIDE4=1 (C++ and CUDA alike).
#include <cstdint>
#include <limits>
#include <vector>

#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"

namespace pb::bvh {

struct alignas(16) Wide4Node {
  float lox[4], hix[4], loy[4], hiy[4], loz[4], hiz[4];
  uint32_t child[4];  // a leaf reference, or a Wide4Node index; an empty slot: a box at +inf, leaf (0, 1)
  uint32_t pad[4];
};
static_assert(sizeof(Wide4Node) == 2 * sizeof(BvhNode), "a Wide4Node is two BvhNode slots");

// The binary BVH's nodes as Wide4Nodes (in BvhNode slots); depth: the wide tree's.
std::vector<BvhNode> collapse_to_wide4(const std::vector<BvhNode>& binary, uint32_t& depth);

namespace detail {

template <class Leaf>
PB_HD bool walk_wide4(const BvhNode* nodes, const Vec3f& o, const Vec3f& d, const float& t, Leaf&& leaf,
                      TraversalStats* stats) {
  const SlabRay sr = make_slab_ray(o, d);
  // A miss, and an empty slot's box at +infinity, which a ray of the +++ octant with t =
  // infinity "enters" at tn = infinity (the binary walk then tests its leaf's one triangle).
  constexpr float kMiss = std::numeric_limits<float>::infinity();
  uint32_t stack[kTraversalStackSize];
  int sp = 0;
  uint32_t ref = 0;
  for (;;) {
    while (!is_leaf(ref)) {
      const Wide4Node* n = reinterpret_cast<const Wide4Node*>(nodes) + ref;
      float lx[4], hx[4], ly[4], hy[4], lz[4], hz[4];
      uint32_t ch[4];
#if defined(__CUDA_ARCH__)
      const float4* p = reinterpret_cast<const float4*>(n);
      const float4 a = __ldg(p), b = __ldg(p + 1), c = __ldg(p + 2), e = __ldg(p + 3), f = __ldg(p + 4),
                   g = __ldg(p + 5);
      const uint4 h = __ldg(reinterpret_cast<const uint4*>(p + 6));
      lx[0] = a.x; lx[1] = a.y; lx[2] = a.z; lx[3] = a.w;
      hx[0] = b.x; hx[1] = b.y; hx[2] = b.z; hx[3] = b.w;
      ly[0] = c.x; ly[1] = c.y; ly[2] = c.z; ly[3] = c.w;
      hy[0] = e.x; hy[1] = e.y; hy[2] = e.z; hy[3] = e.w;
      lz[0] = f.x; lz[1] = f.y; lz[2] = f.z; lz[3] = f.w;
      hz[0] = g.x; hz[1] = g.y; hz[2] = g.z; hz[3] = g.w;
      ch[0] = h.x; ch[1] = h.y; ch[2] = h.z; ch[3] = h.w;
#else
      for (int k = 0; k < 4; ++k) {
        lx[k] = n->lox[k]; hx[k] = n->hix[k]; ly[k] = n->loy[k]; hy[k] = n->hiy[k];
        lz[k] = n->loz[k]; hz[k] = n->hiz[k]; ch[k] = n->child[k];
      }
#endif
      if (stats) ++stats->nodes;
      float key[4];
      for (int k = 0; k < 4; ++k) {
        float tn, tf;
        slab_interval(lx[k], hx[k], ly[k], hy[k], lz[k], hz[k], sr, t, tn, tf);
        key[k] = tn <= tf ? tn : kMiss;
      }
      // Nearest first: a sorting network on (entry distance, child); misses sort last.
      auto cswap = [&](int i, int j) {
        const bool s = key[j] < key[i];
        const float ki = key[i], kj = key[j];
        const uint32_t ci = ch[i], cj = ch[j];
        key[i] = s ? kj : ki; key[j] = s ? ki : kj;
        ch[i] = s ? cj : ci; ch[j] = s ? ci : cj;
      };
      cswap(0, 1); cswap(2, 3); cswap(0, 2); cswap(1, 3); cswap(1, 2);
      if (key[0] == kMiss) {
        if (sp == 0) return false;
        ref = stack[--sp];
        continue;
      }
      ref = ch[0];
      if (key[3] != kMiss) stack[sp++] = ch[3];
      if (key[2] != kMiss) stack[sp++] = ch[2];
      if (key[1] != kMiss) stack[sp++] = ch[1];
    }
    if (leaf(leaf_first(ref), leaf_count(ref))) return true;
    if (sp == 0) return false;
    ref = stack[--sp];
  }
}

}  // namespace detail

// traverse<kAnyHit, kWatertight, 0> of binary_bvh.h over the collapsed nodes.
template <bool kAnyHit, bool kWatertight = true>
PB_HD uint32_t traverse_wide4(const BinaryBvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                              TraversalStats* stats = nullptr) {
  const WatertightRay wr = make_watertight_ray(o, d);
  uint32_t hit = kNoHit, hit_slot = 0;
  float t = t_max;
  const bool stopped = detail::walk_wide4(
      bvh.nodes, o, d, t,
      [&](uint32_t first, uint32_t count) {
        return detail::test_leaf_triangles<kAnyHit, kWatertight>(bvh.tris, first, count, wr, o, d, t_max, false, t,
                                                                 hit, hit_slot, stats);
      },
      stats);
  if (kAnyHit && stopped) {
    t_hit = t;
    return hit;
  }
  return detail::finish_closest<kWatertight>(bvh.tris, o, d, t_max, hit, hit_slot, t, t_hit);
}

}  // namespace pb::bvh
