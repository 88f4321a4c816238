#include "scene_handle.h"

namespace pb::python {

const cpu::EmbreeScene& SceneHandle::embree(bool watertight) const {
  std::lock_guard lock(mutex_);
  auto& e = embree_[watertight ? 1 : 0];
  if (!e) e = cpu::make_embree_scene(scene_, watertight, layout_);
  return *e;
}

const bvh::BvhHost& SceneHandle::bvh() const {
  std::lock_guard lock(mutex_);
  if (!bvh_) bvh_ = std::make_unique<bvh::BvhHost>(bvh::build_bvh(scene_));
  return *bvh_;
}

}  // namespace pb::python
