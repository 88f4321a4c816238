#pragma once
// An Embree device and scene built from pathbench's flat arrays, with Embree's own
// memory use tracked through its memory monitor. The triangles go to Embree one by one
// or paired into quads (EmbreeLayout, settings.h; triangle_pairs.h). Embree's primitive
// ids are then quads: map every hit back to the scene's triangle with triangle().
// Instanced (Scene::instances, embree_instances.cpp): one Embree scene per prototype in
// its own coordinates, an Embree instance per SceneInstance, and one ordinary geometry
// for the rest; a hit (instance, primitive) maps back to the flat triangle, on which the
// path step recomputes the hit as for the flat scene.
#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

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
  // The instanced build (layout Triangles): see InstancingFacts.
  struct Instanced {};
  EmbreeScene(const Scene& scene, bool watertight, Instanced);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  RTCScene handle() const { return scene_; }
  EmbreeLayout layout() const { return choice_.layout; }  // Triangles or Quads, never Auto
  const LayoutChoice& layout_choice() const { return choice_; }  // and why, with the probe's times
  // The scene triangle of a hit on Embree primitive `prim` of instance `inst` (hit.instID[0],
  // RTC_INVALID_GEOMETRY_ID outside instances) at hit coordinates (u, v).
  uint32_t triangle(uint32_t inst, uint32_t prim, float u, float v) const {
    if (!instanced_) return quads_ ? pairs_.triangle_of(prim, u, v) : prim;
    return inst != RTC_INVALID_GEOMETRY_ID ? instance_first_[inst] + prim : rest_[prim];
  }
  uint32_t triangle(const RTCHit& h) const { return triangle(h.instID[0], h.primID, h.u, h.v); }
  // What the instanced build made (instances, prototypes, triangles left flat), and the
  // build's time; instances == 0 for a flat scene.
  struct InstancingFacts {
    size_t instances = 0, prototypes = 0;   // Embree instances and prototype scenes built
    size_t flat_triangles = 0;              // triangles in the ordinary geometry
    size_t instances_left_flat = 0;         // instances that lost triangles to finalize()
  };
  const InstancingFacts& instancing() const { return facts_; }
  bool instanced() const { return instanced_; }
  double build_seconds() const { return build_seconds_; }
  // The quads layout's pairing (which vertices Embree sees in which order), else null.
  const TrianglePairs* pairs() const { return quads_ ? &pairs_ : nullptr; }
  int64_t bytes() const { return bytes_.load(); }
  int64_t peak_bytes() const { return peak_bytes_.load(); }

 private:
  static bool monitor(void* self, ssize_t bytes, bool post);
  void open_device(bool watertight);  // device_, its callbacks, and the (top) scene_
  void commit();                      // commits scene_, throws on an Embree error
  void build_instanced(const Scene& scene, bool watertight);  // embree_instances.cpp
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  LayoutChoice choice_;
  bool quads_ = false;   // choice_.layout == Quads
  TrianglePairs pairs_;  // where quads_
  bool instanced_ = false;
  std::vector<uint32_t> instance_first_;  // per Embree instance id: its first flat triangle
  std::vector<uint32_t> rest_;            // ordinary geometry's primitive -> flat triangle
  std::vector<RTCScene> prototypes_;      // released with the device
  InstancingFacts facts_;
  double build_seconds_ = 0;
  std::atomic<int64_t> bytes_{0};
  std::atomic<int64_t> peak_bytes_{0};
};

// The Embree scene of `scene` in the layout asked for. Auto is resolved before the scene
// is built (choose_embree_layout: measured once per scene per process), and the triangles
// are paired at most once, shared by the layout probe and the scene.
// With --instancing on (and instances in the scene; with quads an InputError) the
// instanced build; Auto traces flat on the CPU (exact; embree_scene.cpp says why).
std::unique_ptr<EmbreeScene> make_embree_scene(const Scene& scene, bool watertight,
                                               EmbreeLayout layout = EmbreeLayout::Auto,
                                               Instancing instancing = Instancing::Off);

}  // namespace pb::cpu
