#pragma once
// The scene on the device (GpuScene's state): the scene's arrays and the flattened BVH
// in device memory, the views the kernels read them through, and the facts of the
// build the report names.
#include <cstdint>

#include "cuda_util.h"
#include "pathbench/common/scene.h"
#include "pathbench/gpu/bvh.h"
#include "pathbench/gpu/render.h"

namespace pb::gpu {

struct GpuScene::Impl {
  DeviceBuffer<Vec3f> positions;
  DeviceBuffer<Triangle> triangles;
  DeviceBuffer<uint32_t> material_ids;
  DeviceBuffer<Material> materials;
  DeviceBuffer<uint32_t> emitters;
  DeviceBuffer<float> emitter_cdf;
  DeviceBuffer<BvhNode> nodes;
  DeviceBuffer<BvhTriangle> tris;
  SceneView view{};
  BvhView bvh{};
  uint64_t bytes = 0;
  uint32_t bvh_depth = 0, bvh_leaves = 0;
  double bvh_sah = 0, bvh_build_seconds = 0;
};

}  // namespace pb::gpu
