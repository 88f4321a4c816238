#pragma once
// Host side of the two-level BVH (two_level_bvh.h): built from Scene::instances with the
// binary BVH builder (bvh_build.h) once per prototype, once for the triangles no instance
// covers and once over the instances' world boxes. Plain C++ (no CUDA).
#include <cstdint>
#include <vector>

#include "pathbench/bvh/bvh_build.h"
#include "pathbench/bvh/two_level_bvh.h"
#include "pathbench/common/scene.h"

namespace pb::bvh {

struct TwoLevelHost {
  std::vector<BvhNode> top_nodes;
  std::vector<uint32_t> top_items;
  std::vector<TwoLevelInstance> instances;  // the scene's instanced ones, then the rest (identity)
  std::vector<BvhNode> bottom_nodes;
  std::vector<uint32_t> bottom_items;
  const Vec3f* positions = nullptr;          // the scene's (host), which must outlive this
  const Triangle* triangles = nullptr;
  uint32_t prototypes = 0;                   // bottom BVHs of prototypes built
  uint32_t instanced = 0;                    // SceneInstances traced as instances
  uint32_t instances_left_flat = 0;          // ...and those that lost triangles to finalize()
  uint32_t flat_triangles = 0;               // triangles in the rest's bottom BVH
  uint32_t top_depth = 0, bottom_depth = 0;  // deepest top and bottom BVH, in inner nodes
  double build_seconds = 0;

  TwoLevelView view() const {
    return {top_nodes.data(), top_items.data(), instances.data(), bottom_nodes.data(), bottom_items.data(),
            positions, triangles};
  }
  // What the structure adds to the scene's arrays (which the traversal reads in place).
  uint64_t bytes() const {
    return (top_nodes.size() + bottom_nodes.size()) * sizeof(BvhNode) + instances.size() * sizeof(TwoLevelInstance) +
           (top_items.size() + bottom_items.size()) * sizeof(uint32_t);
  }
};

TwoLevelHost build_two_level_bvh(const Scene& scene, const BvhBuildOptions& options = {});

}  // namespace pb::bvh
