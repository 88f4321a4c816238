// The scene upload: the BVH built on the host by Embree's builder (bvh_build.cpp), then
// every array copied to the device once; a GpuScene serves many renders.
#include <memory>

#include "device_facts.h"
#include "gpu_scene_impl.cuh"
#include "pathbench/gpu/bvh_build.h"

namespace pb::gpu {

GpuScene::GpuScene(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  ensure_device();
  Impl& m = *impl_;
  const BvhHost bvh = build_bvh(scene);
  const char* lower = "the scene's size (fewer triangles)";
  m.positions.assign(scene.positions, "scene vertices", lower);
  m.triangles.assign(scene.triangles, "scene triangles", lower);
  m.material_ids.assign(scene.material_ids, "material ids", lower);
  m.materials.assign(scene.materials, "materials", lower);
  m.emitters.assign(scene.emitters, "emitter table", lower);
  m.emitter_cdf.assign(scene.emitter_cdf, "emitter table", lower);
  m.nodes.assign(bvh.nodes, "BVH nodes", lower);
  m.tris.assign(bvh.tris, "BVH triangles", lower);
  m.view = scene.view();
  m.view.positions = m.positions.get();
  m.view.triangles = m.triangles.get();
  m.view.material_ids = m.material_ids.get();
  m.view.materials = m.materials.get();
  m.view.emitters = m.emitters.get();
  m.view.emitter_cdf = m.emitter_cdf.get();
  m.bvh = {m.nodes.get(), m.tris.get(), uint32_t(bvh.nodes.size()), uint32_t(bvh.tris.size())};
  m.bytes = m.positions.bytes() + m.triangles.bytes() + m.material_ids.bytes() + m.materials.bytes() +
            m.emitters.bytes() + m.emitter_cdf.bytes() + m.nodes.bytes() + m.tris.bytes();
  m.bvh_depth = bvh.depth;
  m.bvh_leaves = bvh.leaves;
  m.bvh_sah = bvh.sah_cost;
  m.bvh_build_seconds = bvh.build_seconds;
}

GpuScene::~GpuScene() = default;

}  // namespace pb::gpu
