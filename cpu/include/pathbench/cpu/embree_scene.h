#pragma once
// An Embree device and scene built from pathbench's flat arrays, with Embree's own
// memory use tracked through its memory monitor.
#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>

#include "pathbench/common/scene.h"

namespace pb::cpu {

class EmbreeScene {
 public:
  EmbreeScene(const Scene& scene, bool watertight);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene handle() const { return scene_; }
  int64_t bytes() const { return bytes_.load(); }
  int64_t peak_bytes() const { return peak_bytes_.load(); }

 private:
  static bool monitor(void* self, ssize_t bytes, bool post);
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::atomic<int64_t> bytes_{0};
  std::atomic<int64_t> peak_bytes_{0};
};

}  // namespace pb::cpu
