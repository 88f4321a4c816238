// The scene upload: the BVH in the chosen layout built on the host (bvh_layout.cpp, by
// Embree's builder and, for the wide layouts, collapsed), then every array copied to
// the device once; a GpuScene serves many renders.
#include <memory>

#include "device_facts.h"
#include "gpu_scene_impl.cuh"
#include "pathbench/bvh/bvh_layout.h"
#include "bvh_names.h"

namespace pb::gpu {

GpuScene::GpuScene(const Scene& scene) : GpuScene(scene, GpuBvhOptions::from_env()) {}

GpuScene::GpuScene(const Scene& scene, Instancing instancing)
    : GpuScene(scene, GpuBvhOptions::from_env(instancing)) {}

GpuScene::GpuScene(const Scene& scene, const GpuBvhOptions& options) : impl_(std::make_unique<Impl>()) {
  ensure_device();
  Impl& m = *impl_;
  const SceneBvhHost bvh = build_scene_bvh(scene, options);
  const char* lower = "the scene's size (fewer triangles)";
  m.positions.assign(scene.positions, "scene vertices", lower);
  m.triangles.assign(scene.triangles, "scene triangles", lower);
  m.material_ids.assign(scene.material_ids, "material ids", lower);
  m.materials.assign(scene.materials, "materials", lower);
  m.emitters.assign(scene.emitters, "emitter table", lower);
  m.emitter_cdf.assign(scene.emitter_cdf, "emitter table", lower);
  m.nodes.assign(bvh.binary.nodes, "BVH nodes", lower);
  m.wide_nodes.assign(bvh.wide.nodes, "BVH nodes", lower);
  m.leaf_boxes.assign(bvh.leaves, "BVH nodes", lower);
  m.rects.assign(bvh.rects, "BVH nodes", lower);
  const bool binary_tris = bvh.layout == GpuBvhLayout::Binary || bvh.layout == GpuBvhLayout::Leaves ||
                           bvh.layout == GpuBvhLayout::Rects ||  // rects: its leaves, for Moeller-Trumbore
                           bvh.layout == GpuBvhLayout::RectsBinary;  // the rest's, then the rectangles'
  m.tris.assign(bvh.layout == GpuBvhLayout::Brute ? bvh.all : binary_tris ? bvh.binary.tris : bvh.wide.tris,
                "BVH triangles", lower);
  const TwoLevelHost& two = bvh.two_level;
  m.top_nodes.assign(two.top_nodes, "BVH nodes", lower);
  m.bottom_nodes.assign(two.bottom_nodes, "BVH nodes", lower);
  m.top_items.assign(two.top_items, "BVH nodes", lower);
  m.bottom_items.assign(two.bottom_items, "BVH nodes", lower);
  m.instances.assign(two.instances, "BVH instances", lower);
  m.view = scene.view();
  m.view.positions = m.positions.get();
  m.view.triangles = m.triangles.get();
  m.view.material_ids = m.material_ids.get();
  m.view.materials = m.materials.get();
  m.view.emitters = m.emitters.get();
  m.view.emitter_cdf = m.emitter_cdf.get();
  // The host view with the device's pointers in place of the host's.
  m.bvh = bvh.view();
  m.bvh.binary = {m.nodes.get(), m.tris.get(), uint32_t(m.nodes.size()), uint32_t(m.tris.size()), m.bvh.exact_ties};
  m.bvh.wide = {m.wide_nodes.get(), m.tris.get(), uint32_t(m.wide_nodes.size()), uint32_t(m.tris.size()),
                m.bvh.exact_ties};
  m.bvh.tris = m.tris.get();
  m.bvh.leaves = {m.leaf_boxes.get(), m.tris.get(), uint32_t(m.leaf_boxes.size()), uint32_t(m.tris.size()),
                m.bvh.exact_ties};
  if (bvh.layout == GpuBvhLayout::Rects) {  // the leaves layout's kernels, on the rectangles
    m.bvh.leaves.rects = m.rects.get();
    m.bvh.leaves.rect_groups = bvh.rect_groups;
  }
  if (bvh.layout == GpuBvhLayout::RectsBinary) {  // the host view's counts, the device's arrays
    RectsBinaryView& rb = m.bvh.rects_binary;
    rb.rest.nodes = m.nodes.get();
    rb.rest.tris = m.tris.get();
    rb.rects = m.rects.get();
    rb.rect_tris = m.tris.get() + rb.rest.num_tris;
  }
  m.bvh.two_level = {m.top_nodes.get(), m.top_items.get(), m.instances.get(), m.bottom_nodes.get(),
                     m.bottom_items.get(), m.positions.get(), m.triangles.get()};
  m.bvh_bytes = m.nodes.bytes() + m.wide_nodes.bytes() + m.leaf_boxes.bytes() + m.rects.bytes() + m.tris.bytes() + m.top_nodes.bytes() +
                m.bottom_nodes.bytes() + m.top_items.bytes() + m.bottom_items.bytes() + m.instances.bytes();
  m.bytes = m.positions.bytes() + m.triangles.bytes() + m.material_ids.bytes() + m.materials.bytes() +
            m.emitters.bytes() + m.emitter_cdf.bytes() + m.bvh_bytes;
  m.instancing = instancing_report(scene, bvh, options.instancing);
  m.instancing["accel_device_bytes"] = m.bvh_bytes;
  m.layout = bvh.layout;
  m.bvh_nodes = bvh.nodes();
  m.bvh_node_bytes = bvh.node_bytes();
  m.bvh_tris = uint32_t(m.tris.size());
  const bool binary = bvh.layout == GpuBvhLayout::Binary || bvh.layout == GpuBvhLayout::RectsBinary;
  m.bvh_depth = binary ? bvh.binary_depth : bvh.wide.depth;
  m.bvh_treelet_passes = binary ? bvh.binary.treelet_passes : 0;
  m.bvh_leaves = binary ? bvh.binary_leaves : bvh.wide.leaves;
  if (bvh.layout == GpuBvhLayout::Leaves) {  // one level: the leaves
    m.bvh_depth = 1;
    m.bvh_leaves = uint32_t(bvh.leaves.size());
  }
  if (bvh.layout == GpuBvhLayout::Rects) {  // one level: the rectangles
    m.bvh_depth = 1;
    m.bvh_leaves = uint32_t(bvh.rects.size());
  }
  if (bvh.layout == GpuBvhLayout::TwoLevel) {  // the deepest top-to-triangle path; triangle references
    m.bvh_depth = two.top_depth + two.bottom_depth;
    m.bvh_tris = uint32_t(two.bottom_items.size());
  }
  m.bvh_sah = bvh.binary_sah;
  m.bvh_build_seconds = bvh.build_seconds;
}

GpuScene::~GpuScene() = default;

}  // namespace pb::gpu
