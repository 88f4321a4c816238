#pragma once
// An Embree device and scene built from pathbench's flat arrays, with Embree's own
// memory use tracked through its memory monitor. The triangles go to Embree one by one
// or paired into quads (EmbreeLayout, settings.h; triangle_pairs.h). Embree's primitive
// ids are then quads: map every hit back to the scene's triangle with triangle().
#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>
#include <memory>

#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/cpu/embree_layout.h"
#include "pathbench/cpu/triangle_pairs.h"

namespace pb::cpu {

class EmbreeScene {
 public:
  // Builds exactly the layout `choice` names (Triangles or Quads, never Auto: resolving
  // Auto measures, and a constructor should not run a benchmark); `pairs`: the pairing
  // of the scene's triangles where choice.layout is Quads. make_embree_scene, below,
  // resolves both.
  EmbreeScene(const Scene& scene, bool watertight, const LayoutChoice& choice, TrianglePairs pairs = {});
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene handle() const { return scene_; }
  EmbreeLayout layout() const { return choice_.layout; }  // Triangles or Quads, never Auto
  const LayoutChoice& layout_choice() const { return choice_; }  // and why, with the probe's times
  // The scene triangle of a hit on Embree primitive `prim` at hit coordinates (u, v).
  uint32_t triangle(uint32_t prim, float u, float v) const { return quads_ ? pairs_.triangle_of(prim, u, v) : prim; }
  uint32_t triangle(const RTCHit& h) const { return triangle(h.primID, h.u, h.v); }
  // The quads layout's pairing (which vertices Embree sees in which order), else null.
  const TrianglePairs* pairs() const { return quads_ ? &pairs_ : nullptr; }
  int64_t bytes() const { return bytes_.load(); }
  int64_t peak_bytes() const { return peak_bytes_.load(); }

 private:
  static bool monitor(void* self, ssize_t bytes, bool post);
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  LayoutChoice choice_;
  bool quads_ = false;   // choice_.layout == Quads
  TrianglePairs pairs_;  // where quads_
  std::atomic<int64_t> bytes_{0};
  std::atomic<int64_t> peak_bytes_{0};
};

// The Embree scene of `scene` in the layout asked for. Auto is resolved before the scene
// is built (choose_embree_layout: measured once per scene per process), and the triangles
// are paired at most once, shared by the layout probe and the scene.
std::unique_ptr<EmbreeScene> make_embree_scene(const Scene& scene, bool watertight,
                                               EmbreeLayout layout = EmbreeLayout::Auto);

}  // namespace pb::cpu
