#pragma once
// What the kernels trace against: the scene's BVH in the layout it was built in
// (bvh_layout.h picks it), and the one traversal entry that dispatches on it. The
// layout is the same for every thread of a launch, so a run-time switch never
// diverges; but a kernel that holds all three traversals is register-allocated for the
// largest, so the hot kernels are compiled once per kind (kKind, with_traversal_kind)
// and only the rest switch at run time (kAnyKind).
#include <cstdint>
#include <type_traits>

#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/bvh/brute_force.h"
#include "pathbench/bvh/leaf_list.h"
#include "pathbench/bvh/rects_binary.h"
#include "pathbench/bvh/two_level_bvh.h"
#include "pathbench/bvh/wide_bvh.h"
#include "pathbench/common/hd.h"

namespace pb::bvh {

// Binary: binary_bvh.h. Wide: wide_bvh.h (4- or 8-wide, one node format). AllTriangles:
// brute_force.h, the triangles in scene order in `tris` and no nodes. TwoLevel:
// two_level_bvh.h, the instanced scene's (--instancing). Leaves: leaf_list.h, the binary
// BVH's leaves without its inner nodes (tiny scenes without instances). Rects: axis_plane.h,
// the scene's axis-aligned rectangles (in LeafListView::rects), no triangle test.
// RectsBinary: rects_binary.h, the largest rectangles first, then a binary BVH of the rest.
// (5 is kBinaryExactTies below.)
enum class TraversalKind : uint32_t {
  Binary = 0, Wide = 1, AllTriangles = 2, TwoLevel = 3, Leaves = 4, Rects = 6, RectsBinary = 7
};

struct BvhView {
  BvhView() = default;
  // A binary BVH alone (BvhHost::view()) is a BvhView as it stands.
  PB_HD BvhView(const BinaryBvhView& b) : kind(TraversalKind::Binary), binary(b) {}  // NOLINT: implicit on purpose
  TraversalKind kind = TraversalKind::Binary;
  BinaryBvhView binary{};
  WideBvhView wide{};
  const BvhTriangle* tris = nullptr;  // AllTriangles
  uint32_t num_tris = 0;
  uint32_t exact_ties = 0;            // AllTriangles: as BinaryBvhView's
  TwoLevelView two_level{};
  LeafListView leaves{};
  RectsBinaryView rects_binary{};
};

// kKind: a TraversalKind the caller was compiled for (bvh.kind must be it), or
// kAnyKind to switch on bvh.kind. kBinaryExactTies: the binary BVH of a scene with
// instances traced flat (exact_ties set), compiled apart from Binary (exact_ties unset)
// so that flat scenes' kernels carry no tie compare (binary_bvh.h's traverse, kExact).
constexpr int kAnyKind = -1;
constexpr int kBinaryExactTies = 5;

template <bool kAnyHit, bool kWatertight = true, int kKind = kAnyKind>
PB_HD uint32_t traverse(const BvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                        TraversalStats* stats = nullptr) {
  if constexpr (kKind == int(TraversalKind::Wide)) {
    return traverse_wide<kAnyHit, kWatertight>(bvh.wide, o, d, t_max, t_hit, stats);
  } else if constexpr (kKind == int(TraversalKind::AllTriangles)) {
    return traverse_all<kAnyHit, kWatertight>(bvh.tris, bvh.num_tris, o, d, t_max, t_hit, stats, bvh.exact_ties != 0);
  } else if constexpr (kKind == int(TraversalKind::Binary)) {
    return traverse<kAnyHit, kWatertight, 0>(bvh.binary, o, d, t_max, t_hit, stats);
  } else if constexpr (kKind == kBinaryExactTies) {
    return traverse<kAnyHit, kWatertight, 1>(bvh.binary, o, d, t_max, t_hit, stats);
  } else if constexpr (kKind == int(TraversalKind::TwoLevel)) {
    return traverse_two_level<kAnyHit, kWatertight>(bvh.two_level, o, d, t_max, t_hit, stats);
  } else if constexpr (kKind == int(TraversalKind::Leaves)) {
    return traverse_leaves<kAnyHit, kWatertight, 0>(bvh.leaves, o, d, t_max, t_hit, stats);  // no instances: no ties rule
  } else if constexpr (kKind == int(TraversalKind::Rects) && kWatertight) {
    return traverse_rects<kAnyHit>(bvh.leaves.rects, bvh.leaves.rect_groups, o, d, t_max, t_hit, stats);
  } else if constexpr (kKind == int(TraversalKind::Rects)) {  // Moeller-Trumbore asked for: the leaves it keeps
    return traverse_leaves<kAnyHit, false, 0>(bvh.leaves, o, d, t_max, t_hit, stats);
  } else if constexpr (kKind == int(TraversalKind::RectsBinary)) {
    return traverse_rects_binary<kAnyHit, kWatertight>(bvh.rects_binary, o, d, t_max, t_hit, stats);
  } else {
    switch (bvh.kind) {
      case TraversalKind::Wide: return traverse_wide<kAnyHit, kWatertight>(bvh.wide, o, d, t_max, t_hit, stats);
      case TraversalKind::TwoLevel:
        return traverse_two_level<kAnyHit, kWatertight>(bvh.two_level, o, d, t_max, t_hit, stats);
      case TraversalKind::AllTriangles:
        return traverse_all<kAnyHit, kWatertight>(bvh.tris, bvh.num_tris, o, d, t_max, t_hit, stats, bvh.exact_ties != 0);
      case TraversalKind::Leaves: return traverse_leaves<kAnyHit, kWatertight>(bvh.leaves, o, d, t_max, t_hit, stats);
      case TraversalKind::Rects:  // a triangle test (Moeller-Trumbore) asked for: the leaves the layout keeps
        if constexpr (!kWatertight) return traverse_leaves<kAnyHit, false>(bvh.leaves, o, d, t_max, t_hit, stats);
        else return traverse_rects<kAnyHit>(bvh.leaves.rects, bvh.leaves.rect_groups, o, d, t_max, t_hit, stats);
      case TraversalKind::RectsBinary:
        return traverse_rects_binary<kAnyHit, kWatertight>(bvh.rects_binary, o, d, t_max, t_hit, stats);
      default: return traverse<kAnyHit, kWatertight>(bvh.binary, o, d, t_max, t_hit, stats);
    }
  }
}

template <bool kWatertight = true, int kKind = kAnyKind>
PB_HD uint32_t intersect_closest(const BvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit) {
  return traverse<false, kWatertight, kKind>(bvh, o, d, t_max, t_hit);
}
template <bool kWatertight = true, int kKind = kAnyKind>
PB_HD bool occluded(const BvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max) {
  float t;
  return traverse<true, kWatertight, kKind>(bvh, o, d, t_max, t) != kNoHit;
}

// Calls fn(std::integral_constant<int, kind>{}) for the view's kind (kBinaryExactTies for
// a binary BVH with exact_ties): picks the kernel compiled for it (host code).
template <class Fn>
decltype(auto) with_traversal_kind(const BvhView& bvh, Fn&& fn) {
  if (bvh.kind == TraversalKind::Binary && bvh.binary.exact_ties)
    return fn(std::integral_constant<int, kBinaryExactTies>{});
  switch (bvh.kind) {
    case TraversalKind::Wide: return fn(std::integral_constant<int, int(TraversalKind::Wide)>{});
    case TraversalKind::AllTriangles: return fn(std::integral_constant<int, int(TraversalKind::AllTriangles)>{});
    case TraversalKind::TwoLevel: return fn(std::integral_constant<int, int(TraversalKind::TwoLevel)>{});
    case TraversalKind::Leaves: return fn(std::integral_constant<int, int(TraversalKind::Leaves)>{});
    case TraversalKind::Rects: return fn(std::integral_constant<int, int(TraversalKind::Rects)>{});
    case TraversalKind::RectsBinary: return fn(std::integral_constant<int, int(TraversalKind::RectsBinary)>{});
    default: return fn(std::integral_constant<int, int(TraversalKind::Binary)>{});
  }
}

}  // namespace pb::bvh
