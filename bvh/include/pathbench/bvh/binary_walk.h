#pragma once
// The binary BVH's walk (binary_bvh.h) as a state that stops and resumes: one step walks
// inner nodes down to the next leaf and tests its triangles. The GPU's refill megakernel
// (gpu/src/pixel_refill.cu) keeps one walk a lane and steps the warp's walks together, so
// that a lane whose ray is done takes its path's next ray while the others walk on
// (Aila & Laine 2009, "replacing terminated rays"). Closest hit or any hit is the walk's
// own run-time choice, since a warp steps both kinds at once.
//
// Every decision is walk_binary's and traverse<kAnyHit, true, 0>'s (watertight test, no
// tie rule: scenes without instances): the same nodes in the same order against the same
// t, so the same triangle (host test: tests/gpu/test_binary_walk.cpp).
#include <cstdint>

#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"
#include "pathbench/common/watertight.h"

namespace pb::bvh {

struct BinaryWalk {
  detail::SlabRay sr;
  WatertightRay wr;
  float t;         // the best distance so far (t_max until a hit)
  uint32_t hit;    // the scene triangle id, or kNoHit
  uint32_t ref;    // the node or leaf the walk is at
  int sp;          // entries on the caller's stack
  bool any_hit;

  // The stack lives apart from the state (the caller's array): kept inside a struct that
  // is copied or indexed, the whole aggregate goes to local memory (gpu-log, "Wide BVH").
  PB_HD void begin(const Vec3f& o, const Vec3f& d, float t_max, bool any) {
    sr = detail::make_slab_ray(o, d);
    wr = make_watertight_ray(o, d);
    t = t_max;
    hit = kNoHit;
    ref = 0;
    sp = 0;
    any_hit = any;
  }

  // Walks to the next leaf and tests it; true when the walk is over (hit and t are its
  // answer: closest_hit's triangle id before finish_closest, or an any-hit's).
  PB_HD bool step(const BinaryBvhView& bvh, uint32_t (&stack)[kTraversalStackSize]) {
    while (!is_leaf(ref)) {
      float x[4], y[4], z[4];
      uint32_t child[2];
      detail::load_node(bvh.nodes, ref, x, y, z, child);
      float tn[2], tf[2];
      for (int c = 0; c < 2; ++c)
        detail::slab_interval(x[2 * c], x[2 * c + 1], y[2 * c], y[2 * c + 1], z[2 * c], z[2 * c + 1], sr, t, tn[c],
                              tf[c]);
      const bool h0 = tn[0] <= tf[0], h1 = tn[1] <= tf[1];
      if (h0 && h1) {
        const bool swap = tn[1] < tn[0];
        ref = swap ? child[1] : child[0];
        stack[sp++] = swap ? child[0] : child[1];
      } else if (h0 || h1) {
        ref = h0 ? child[0] : child[1];
      } else {
        if (sp == 0) return true;
        ref = stack[--sp];
      }
    }
    // test_vertices<true> without the tie rule: a hit before t narrows it.
    const uint32_t first = leaf_first(ref), end = first + leaf_count(ref);
    for (uint32_t i = first; i < end; ++i) {
      Vec3f a, b, c;
      uint32_t prim;
      detail::load_triangle(bvh.tris, i, a, b, c, prim);
      float tt;
      if (intersect_watertight(wr, a, b, c, t, tt)) {
        t = tt;
        hit = prim;
        if (any_hit) return true;
      }
    }
    if (sp == 0) return true;
    ref = stack[--sp];
    return false;
  }
};

// The whole walk at once (the host's check of the GPU's steps): traverse<any_hit, true, 0>'s
// triangle id.
PB_HD uint32_t walk_to_end(const BinaryBvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, bool any_hit) {
  BinaryWalk w;
  uint32_t stack[kTraversalStackSize];
  w.begin(o, d, t_max, any_hit);
  while (!w.step(bvh, stack)) {
  }
  return w.hit;
}

}  // namespace pb::bvh
