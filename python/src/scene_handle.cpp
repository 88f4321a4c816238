#include "scene_handle.h"

#include <fmt/core.h>

#include <cmath>

#include "pathbench/common/errors.h"

namespace pb::python {

Scene transformed(Scene s, float scale, Vec3f offset) {
  if (!(std::isfinite(scale) && scale > 0.0f))
    throw InputError(fmt::format("scale must be finite and positive, got {}", scale));
  if (!(std::isfinite(offset.x) && std::isfinite(offset.y) && std::isfinite(offset.z)))
    throw InputError(fmt::format("offset must be finite, got ({}, {}, {})", offset.x, offset.y, offset.z));
  if (scale == 1.0f && offset.x == 0.0f && offset.y == 0.0f && offset.z == 0.0f) return s;
  for (Vec3f& p : s.positions) p = p * scale + offset;
  s.camera.position = s.camera.position * scale + offset;
  s.finalize();
  return s;
}

const cpu::EmbreeScene& SceneHandle::embree(bool watertight) const {
  std::lock_guard lock(mutex_);
  auto& e = embree_[watertight ? 1 : 0];
  if (!e) e = cpu::make_embree_scene(scene_, watertight);
  return *e;
}

const gpu::BvhHost& SceneHandle::bvh() const {
  std::lock_guard lock(mutex_);
  if (!bvh_) bvh_ = std::make_unique<gpu::BvhHost>(gpu::build_bvh(scene_));
  return *bvh_;
}

}  // namespace pb::python
