#pragma once
// Host side of the GPU BVH: built with Embree's BVH builder (rtcNewBVH / rtcBuildBVH,
// binned SAH, pathbench's own node type), then flattened into BvhNode / BvhTriangle
// arrays ready to upload. Plain C++: the host-side traversal tests use it without CUDA.
#include <cstdint>
#include <vector>

#include "pathbench/bvh/binary_bvh.h"
#include "pathbench/bvh/traversal.h"  // BvhView: what view() converts to for the dispatching traversal
#include "pathbench/common/scene.h"

namespace pb::bvh {

struct BvhBuildOptions {
  unsigned max_leaf_size = 4;     // <= kMaxLeafPrims
  float traversal_cost = 1.0f;    // SAH cost of visiting a node, relative to...
  float intersection_cost = 1.0f; // ...testing one triangle
  bool high_quality = false;      // Embree's HIGH quality (spatial splits)
  // Treelet restructuring passes after the build (bvh_optimize.cpp). Measured on an H100,
  // interleaved (docs/notes/gpu-log.md, "Treelet restructuring"): 3 passes took the pixel
  // megakernel 4-6 % faster on the suite's meshes; 0 leaves Embree's tree as built.
  unsigned optimize_passes = 3;
  // These options with the environment's overrides, for measuring builds without
  // rebuilding: PATHBENCH_GPU_BVH_LEAF_SIZE=1..16, PATHBENCH_GPU_BVH_QUALITY=medium|high,
  // PATHBENCH_GPU_BVH_TRAVERSAL_COST=<x>, PATHBENCH_GPU_BVH_INTERSECTION_COST=<x> (x > 0),
  // PATHBENCH_GPU_BVH_OPTIMIZE=0..8 (treelet restructuring passes).
  // Throws InputError naming the variable for a value it cannot use.
  BvhBuildOptions with_env() const;
};

struct BvhHost {
  std::vector<BvhNode> nodes;
  std::vector<BvhTriangle> tris;
  uint32_t depth = 0;       // longest root-to-leaf path, in inner nodes
  uint32_t leaves = 0;
  double sah_cost = 0;      // expected cost of a random ray, in the options' units
  double build_seconds = 0;
  float pad = 0;            // every box was grown by this (a few ulps of the largest coordinate)
  uint32_t treelet_passes = 0;  // treelet restructuring passes the tree went through (optimize_treelets)

  BinaryBvhView view() const {
    return {nodes.data(), tris.data(), uint32_t(nodes.size()), uint32_t(tris.size())};
  }
  uint64_t bytes() const { return nodes.size() * sizeof(BvhNode) + tris.size() * sizeof(BvhTriangle); }
};

// Treelet restructuring (Karras & Aila 2013) of a flattened binary BVH, in place: `passes`
// bottom-up passes, each node's treelet of up to 7 subtrees rearranged into the binary tree of
// least SAH cost; the nodes then renumbered depth first. (It may deepen the tree: build_bvh
// builds again without it where the result is deeper than the traversal stack allows.)
struct BvhOptimizeResult {
  double cost_before = 0, cost_after = 0;  // SAH cost of the stored (padded) boxes, unnormalised
  uint32_t depth = 0;                      // in inner nodes, as BvhHost::depth
};
BvhOptimizeResult optimize_treelets(std::vector<BvhNode>& nodes, const BvhBuildOptions& options);

// Scene triangle `id` as the traversals' 48-byte record (its vertices and id).
BvhTriangle bvh_triangle(const Scene& scene, uint32_t id);

// `leave_out` (one flag a scene triangle, or null): the triangles flagged are not in the
// BVH (the rects-binary layout traces them as rectangles); the others keep their scene ids.
BvhHost build_bvh(const Scene& scene, const BvhBuildOptions& options = {}, const std::vector<char>* leave_out = nullptr);

}  // namespace pb::bvh
