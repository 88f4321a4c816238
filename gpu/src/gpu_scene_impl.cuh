#pragma once
// The scene on the device (GpuScene's state): the scene's arrays and the flattened BVH
// in device memory, the views the kernels read them through, and the facts of the
// build the report names.
#include <cstdint>

#include <nlohmann/json.hpp>

#include "cuda_util.h"
#include "pathbench/common/scene.h"
#include "pathbench/bvh/bvh_layout.h"
#include "pathbench/bvh/traversal.h"
#include "pathbench/gpu/render.h"
#include "bvh_names.h"

namespace pb::gpu {

struct GpuScene::Impl {
  DeviceBuffer<Vec3f> positions;
  DeviceBuffer<Triangle> triangles;
  DeviceBuffer<uint32_t> material_ids;
  DeviceBuffer<Material> materials;
  DeviceBuffer<uint32_t> emitters;
  DeviceBuffer<float> emitter_cdf;
  DeviceBuffer<BvhNode> nodes;      // the layout's nodes: binary...
  DeviceBuffer<WideNode> wide_nodes;  // ...or wide (brute force has none)
  DeviceBuffer<LeafBox> leaf_boxes;  // ...or the leaves layout's boxes
  DeviceBuffer<AxisRect> rects;      // ...or the rects layout's rectangles (axis_plane.h)
  DeviceBuffer<BvhTriangle> tris;    // in traversal order (brute force: scene order)
  // The two-level BVH's (two_level_bvh.h; its triangles are `positions` and `triangles`).
  DeviceBuffer<BvhNode> top_nodes, bottom_nodes;
  DeviceBuffer<uint32_t> top_items, bottom_items;
  DeviceBuffer<TwoLevelInstance> instances;
  SceneView view{};
  BvhView bvh{};
  uint64_t bytes = 0;
  GpuBvhLayout layout = GpuBvhLayout::Binary;
  uint32_t bvh_nodes = 0, bvh_node_bytes = 0, bvh_tris = 0;
  uint32_t bvh_depth = 0, bvh_leaves = 0, bvh_treelet_passes = 0;
  double bvh_sah = 0, bvh_build_seconds = 0;
  uint64_t bvh_bytes = 0;  // the acceleration structure's part of `bytes`
  nlohmann::json instancing;  // what the report says of --instancing (scene_upload.cu)
};

}  // namespace pb::gpu
