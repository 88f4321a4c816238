#pragma once
// A loaded scene as the Python module holds it: the finalized pb::Scene plus the
// acceleration structures the ray casts need, built on first use and kept, so a
// script casting many batches pays for each build once.
#include <memory>
#include <mutex>
#include <string>

#include "pathbench/common/scene.h"
#include "pathbench/cpu/embree_scene.h"
#include "pathbench/bvh/bvh_build.h"

namespace pb::python {

class SceneHandle {
 public:
  // `layout`: how the Embree scene takes the triangles (--embree-layout; auto times both).
  explicit SceneHandle(Scene scene, EmbreeLayout layout = EmbreeLayout::Auto)
      : scene_(std::move(scene)), layout_(layout) {}
  const Scene& scene() const { return scene_; }

  // The CPU tracer's Embree scene (make_embree_scene(scene, watertight, layout)), built once per flag.
  const cpu::EmbreeScene& embree(bool watertight) const;
  // The GPU tracer's BVH (build_bvh with its default options), kept on the host.
  const bvh::BvhHost& bvh() const;

 private:
  Scene scene_;
  EmbreeLayout layout_;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<cpu::EmbreeScene> embree_[2];  // [watertight]
  mutable std::unique_ptr<bvh::BvhHost> bvh_;
};

}  // namespace pb::python
