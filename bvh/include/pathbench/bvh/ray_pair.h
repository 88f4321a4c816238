#pragma once
// Two independent rays of one path in one walk: the shadow segment of vertex i and the ray
// that leaves it (the closest-hit query that finds vertex i + 1, or the last vertex's shadow
// segment). A path's rays are otherwise sequential, but these two depend only on vertex i.
// Traced one after the other, a warp of the pixel megakernel walks each at the pace of its
// slowest lane: max(shadow) + max(closest) node steps. Walked as one sequence in one loop, it
// pays max(shadow + closest), and a lane that finished its shadow segment early goes on with
// its next ray while the others still walk (a host model over real path rays: 8 % fewer warp
// node steps on the 2-bounce meshes, 19 % on glass-dragon; docs/notes/gpu-log.md).
// Each ray is traced exactly as traverse() traces it alone, so every answer, and every image,
// is the same bit for bit. The binary BVH (with or without the exact tie rule) has the joint
// walk; the other layouts trace the two rays one after the other.
#include <cstdint>

#include "pathbench/bvh/traversal.h"
#include "pathbench/common/hd.h"

namespace pb::bvh {

enum class SecondRay : uint32_t { None = 0, Shadow = 1, Closest = 2 };

// The second ray's answer: for Closest the hit triangle (or kNoHit) and its t as
// intersect_closest gives them; for Shadow hit != kNoHit when the segment is blocked.
struct PairAnswer {
  bool first_blocked = false;
  uint32_t hit = kNoHit;
  float t = 0.0f;
};

namespace detail {

// The per-ray constants a binary walk reads.
struct WalkRay {
  SlabRay sr;
  WatertightRay wr;
  Vec3f o, d;
};
PB_HD WalkRay make_walk_ray(const Vec3f& o, const Vec3f& d) { return {make_slab_ray(o, d), make_watertight_ray(o, d), o, d}; }

// A stack entry that is no node and no leaf (a leaf's first + count never passes
// kLeafFirstMask): below the first ray's entries, it is where the first ray ends and the
// second begins. The switch is then one more kind of leaf in the one loop, not a loop of its own.
constexpr uint32_t kSwitchRef = kLeafBit | kLeafFirstMask;

// The joint walk over a binary BVH: the first ray (a shadow segment, if has_first) then the
// second, each front to back exactly as walk_binary + traverse do it alone.
template <bool kWatertight, int kExact>
PB_HD PairAnswer walk_pair_binary(const BinaryBvhView& bvh, bool has_first, const Vec3f& o0, const Vec3f& d0,
                                  SecondRay second_kind, const Vec3f& o1, const Vec3f& d1) {
  constexpr float kInfinity = __builtin_huge_valf();
  const bool exact = kExact < 0 ? bvh.exact_ties != 0 : kExact == 1;
  PairAnswer out;
  if (!has_first && second_kind == SecondRay::None) return out;
  const bool two = has_first && second_kind != SecondRay::None;
  bool on_second = !has_first;
  WalkRay r = make_walk_ray(on_second ? o1 : o0, on_second ? d1 : d0);
  bool any_hit = on_second ? second_kind == SecondRay::Shadow : true;
  float t_max = any_hit ? 1.0f : kInfinity;
  float t = t_max;
  uint32_t hit = kNoHit, hit_slot = 0;
  uint32_t stack[kTraversalStackSize + 1];
  int sp = 0;
  if (two) stack[sp++] = kSwitchRef;
  uint32_t ref = 0;
  for (;;) {
    bool finished = false;
    while (!is_leaf(ref)) {
      float x[4], y[4], z[4];
      uint32_t child[2];
      load_node(bvh.nodes, ref, x, y, z, child);
      float tn[2], tf[2];
      for (int c = 0; c < 2; ++c)
        slab_interval(x[2 * c], x[2 * c + 1], y[2 * c], y[2 * c + 1], z[2 * c], z[2 * c + 1], r.sr, t, tn[c], tf[c]);
      const bool h0 = tn[0] <= tf[0], h1 = tn[1] <= tf[1];
      if (h0 && h1) {
        const bool swap = tn[1] < tn[0];
        ref = swap ? child[1] : child[0];
        stack[sp++] = swap ? child[0] : child[1];
      } else if (h0 || h1) {
        ref = h0 ? child[0] : child[1];
      } else if (sp == 0) {
        finished = true;
        break;
      } else {
        ref = stack[--sp];
      }
    }
    if (finished) break;
    if (ref == kSwitchRef) {  // the first ray is answered: the lane goes on with the second
      out.first_blocked = hit != kNoHit;
      on_second = true;
      r = make_walk_ray(o1, d1);
      any_hit = second_kind == SecondRay::Shadow;
      t_max = any_hit ? 1.0f : kInfinity;
      t = t_max;
      hit = kNoHit;
      ref = 0;
    } else {
      const uint32_t first = leaf_first(ref), count = leaf_count(ref);
      bool answered = false;
      for (uint32_t i = first; i < first + count; ++i)
        if (test_triangle<kWatertight>(bvh.tris, i, r.wr, r.o, r.d, t_max, exact, t, hit, hit_slot, nullptr) && any_hit) {
          answered = true;
          break;
        }
      if (answered) {
        if (on_second || !two) break;
        sp = 1;  // what is left of the first ray's walk: the switch entry
      }
      if (sp == 0) break;
      ref = stack[--sp];
    }
  }
  if (!on_second) {  // no second ray
    out.first_blocked = hit != kNoHit;
    return out;
  }
  if (any_hit) {
    out.hit = hit;
    out.t = t;
  } else {
    out.hit = finish_closest<kWatertight>(bvh.tris, r.o, r.d, t_max, hit, hit_slot, t, out.t);
  }
  return out;
}

}  // namespace detail

// The shadow segment (o0, d0) (t in (t_min, 1); has_first false: none) and then the second ray
// (o1, d1) of kind second_kind (Closest: t up to infinity; Shadow: up to 1; None: none).
template <bool kWatertight = true, int kKind = kAnyKind>
PB_HD PairAnswer trace_pair(const BvhView& bvh, bool has_first, const Vec3f& o0, const Vec3f& d0,
                            SecondRay second_kind, const Vec3f& o1, const Vec3f& d1) {
  if constexpr (kKind == int(TraversalKind::Binary)) {
    return detail::walk_pair_binary<kWatertight, 0>(bvh.binary, has_first, o0, d0, second_kind, o1, d1);
  } else if constexpr (kKind == kBinaryExactTies) {
    return detail::walk_pair_binary<kWatertight, 1>(bvh.binary, has_first, o0, d0, second_kind, o1, d1);
  } else {
    PairAnswer out;
    if (has_first) out.first_blocked = occluded<kWatertight, kKind>(bvh, o0, d0, 1.0f);
    if (second_kind == SecondRay::Shadow) out.hit = traverse<true, kWatertight, kKind>(bvh, o1, d1, 1.0f, out.t);
    else if (second_kind == SecondRay::Closest)
      out.hit = traverse<false, kWatertight, kKind>(bvh, o1, d1, __builtin_huge_valf(), out.t);
    return out;
  }
}

}  // namespace pb::bvh
