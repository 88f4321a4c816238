#pragma once
// What the kernels trace against: the scene's BVH in the layout it was built in
// (bvh_layout.h picks it), and the one traversal entry that dispatches on it. The
// layout is the same for every thread of a launch, so the switch never diverges.
#include <cstdint>

#include "pathbench/common/hd.h"
#include "pathbench/gpu/brute_force.h"
#include "pathbench/gpu/bvh.h"
#include "pathbench/gpu/wide_bvh.h"

namespace pb::gpu {

// Binary: bvh.h. Wide: wide_bvh.h (4- or 8-wide, one node format). AllTriangles:
// brute_force.h, the triangles in scene order in `tris` and no nodes.
enum class TraversalKind : uint32_t { Binary = 0, Wide = 1, AllTriangles = 2 };

struct BvhView {
  BvhView() = default;
  // A binary BVH alone (BvhHost::view()) is a BvhView as it stands.
  PB_HD BvhView(const BinaryBvhView& b) : kind(TraversalKind::Binary), binary(b) {}  // NOLINT: implicit on purpose
  TraversalKind kind = TraversalKind::Binary;
  BinaryBvhView binary{};
  WideBvhView wide{};
  const BvhTriangle* tris = nullptr;  // AllTriangles
  uint32_t num_tris = 0;
};

template <bool kAnyHit, bool kWatertight = true>
PB_HD uint32_t traverse(const BvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                        TraversalStats* stats = nullptr) {
  switch (bvh.kind) {
    case TraversalKind::Wide: return traverse_wide<kAnyHit, kWatertight>(bvh.wide, o, d, t_max, t_hit, stats);
    case TraversalKind::AllTriangles:
      return traverse_all<kAnyHit, kWatertight>(bvh.tris, bvh.num_tris, o, d, t_max, t_hit, stats);
    default: return traverse<kAnyHit, kWatertight>(bvh.binary, o, d, t_max, t_hit, stats);
  }
}

template <bool kWatertight = true>
PB_HD uint32_t intersect_closest(const BvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit) {
  return traverse<false, kWatertight>(bvh, o, d, t_max, t_hit);
}
template <bool kWatertight = true>
PB_HD bool occluded(const BvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max) {
  float t;
  return traverse<true, kWatertight>(bvh, o, d, t_max, t) != kNoHit;
}

}  // namespace pb::gpu
