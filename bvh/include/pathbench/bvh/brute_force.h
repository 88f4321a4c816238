#pragma once
// Tiny scenes without a BVH: every triangle tested, in scene order. Under a few dozen
// triangles this beats any traversal on the GPU: no stack, no box tests, and a warp's
// lanes all read the same triangle at the same time (one broadcast load from L1 for the
// whole warp) and never diverge in the loop. Host+device, as the BVH traversals.
#include <cstdint>

#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"

namespace pb::bvh {

// Closest hit (kAnyHit = false) or any hit among tris[0..n), as traverse() in binary_bvh.h:
// same triangle test, so the same answer (of two triangles at exactly the same t, the
// lower id: detail::closer).
template <bool kAnyHit, bool kWatertight = true>
PB_HD uint32_t traverse_all(const BvhTriangle* tris, uint32_t n, const Vec3f& o, const Vec3f& d, float t_max,
                            float& t_hit, TraversalStats* stats = nullptr, bool exact_ties = false) {
  const WatertightRay wr = make_watertight_ray(o, d);
  uint32_t hit = kNoHit, hit_slot = 0;
  float t = t_max;
  for (uint32_t i = 0; i < n; ++i) {
    if (detail::test_triangle<kWatertight>(tris, i, wr, o, d, t_max, exact_ties, t, hit, hit_slot, stats) && kAnyHit) {
      t_hit = t;
      return hit;
    }
  }
  return detail::finish_closest<kWatertight>(tris, o, d, t_max, hit, hit_slot, t, t_hit);
}

}  // namespace pb::bvh
