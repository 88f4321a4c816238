#pragma once
// Tiny scenes without inner nodes (GpuBvhLayout::Leaves): the binary BVH's leaves in one
// list, each with the box its parent held for it. In a closed room every inner box of
// a BVH spans the room (paper-cornell: a closest hit visits 5 of the 6 nodes, two boxes
// each, with a stack), so the hierarchy costs more than it saves. Here a ray tests
// every leaf's box once, in one loop that all lanes of a warp run alike (every lane
// reads the same leaf: one broadcast load), keeps the leaves it entered as a bit mask,
// and then tests the triangles of those: the nearest box first, the others again
// against the t that found (a closest hit), or in order until one is hit (any hit).
// Same box test as the binary BVH's last level (detail::slab_interval on the same
// padded boxes) and the same triangle test, so the same hits (hit_tests.h's rules on ties).
// Host+device, as the other traversals.
#include <cstdint>
#include <limits>

#include "pathbench/bvh/axis_plane.h"
#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"

namespace pb::bvh {

// One leaf: its box and its triangles (make_leaf_ref(first, count)), two 16-byte loads.
struct alignas(16) LeafBox {
  float lo[3];
  uint32_t ref;
  float hi[3];
  uint32_t pad;
};
static_assert(sizeof(LeafBox) == 32, "LeafBox is two 16-byte loads");

struct LeafListView {
  const LeafBox* leaves;
  const BvhTriangle* tris;  // in leaf order, as the binary BVH's
  uint32_t num_leaves;
  uint32_t num_tris;
  uint32_t exact_ties = 0;  // as BinaryBvhView's
  // GpuBvhLayout::Rects (axis_plane.h, TraversalKind::Rects): the scene as axis-aligned
  // rectangles, traced instead of the leaves (no boxes, no triangle tests).
  const AxisRect* rects = nullptr;
  RectGroups rect_groups{};
};

// Leaves a ray keeps in one mask: larger scenes are walked 32 leaves at a time.
constexpr uint32_t kLeafGroup = 32;

namespace detail {

PB_HD void load_leaf(const LeafBox* leaves, uint32_t i, float (&lo)[3], float (&hi)[3], uint32_t& ref) {
  uint32_t pad;
  load_box_record(leaves, i, lo, hi, ref, pad);
}

// Leaf i's box entered before t (slab_interval, as a binary node's child); its ref.
PB_HD bool enters_leaf(const LeafBox* leaves, uint32_t i, const SlabRay& sr, float t, float& tn, uint32_t& ref) {
  float lo[3], hi[3];
  load_leaf(leaves, i, lo, hi, ref);
  float tf;
  slab_interval(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], sr, t, tn, tf);
  return tn <= tf;
}

}  // namespace detail

// Closest hit (kAnyHit = false) or any hit, as traverse() in binary_bvh.h (kExact likewise).
template <bool kAnyHit, bool kWatertight = true, int kExact = -1>
PB_HD uint32_t traverse_leaves(const LeafListView& f, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                             TraversalStats* stats = nullptr) {
  const bool exact = kExact < 0 ? f.exact_ties != 0 : kExact == 1;
  const WatertightRay wr = make_watertight_ray(o, d);
  const detail::SlabRay sr = detail::make_slab_ray(o, d);
  uint32_t hit = kNoHit, hit_slot = 0;
  float t = t_max;
  auto test_leaf = [&](uint32_t ref) {  // true: an any-hit query is answered
    return detail::test_leaf_triangles<kAnyHit, kWatertight>(f.tris, leaf_first(ref), leaf_count(ref), wr, o, d, t_max,
                                                             exact, t, hit, hit_slot, stats);
  };
  for (uint32_t group = 0; group < f.num_leaves; group += kLeafGroup) {
    const uint32_t n = f.num_leaves - group < kLeafGroup ? f.num_leaves - group : kLeafGroup;
    uint32_t entered = 0, nearest = 0;
    float nearest_tn = std::numeric_limits<float>::infinity();
    for (uint32_t k = 0; k < n; ++k) {
      float tn;
      uint32_t ref;
      if (stats) ++stats->nodes;
      if (detail::enters_leaf(f.leaves, group + k, sr, t, tn, ref)) {
        entered |= 1u << k;
        if (tn < nearest_tn) {
          nearest_tn = tn;
          nearest = k;
        }
      }
    }
    if (kAnyHit) {
      for (; entered != 0; entered &= entered - 1) {
        float lo[3], hi[3];
        uint32_t ref;
        detail::load_leaf(f.leaves, group + detail::lowest_bit(entered), lo, hi, ref);
        if (test_leaf(ref)) {
          t_hit = t;
          return hit;
        }
      }
    } else {
      // The nearest box first: a hit there narrows t, and each other box entered is
      // tested again against it (a closed room: mostly none is left).
      for (uint32_t k = nearest; entered != 0; k = entered != 0 ? detail::lowest_bit(entered) : 0) {
        entered &= ~(1u << k);
        float tn;
        uint32_t ref;
        if (detail::enters_leaf(f.leaves, group + k, sr, t, tn, ref)) test_leaf(ref);
      }
    }
  }
  return detail::finish_closest<kWatertight>(f.tris, o, d, t_max, hit, hit_slot, t, t_hit);
}

}  // namespace pb::bvh
