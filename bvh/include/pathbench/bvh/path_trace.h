#pragma once
// One path through the GPU's BVH, as the pixel megakernel traces it: host+device, so
// that a CPU can compute exactly the GPU's samples (host_tracer.h; the hybrid CPU+GPU
// render's CPU ranks). Same BVH, same triangle test (traversal.h), same path step
// (common/path.h), same rounding (--fmad=false on the device, -ffp-contract=off here).
#include <cstdint>
#include <limits>

#include "pathbench/bvh/traversal.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/path.h"

namespace pb::bvh {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The last-vertex shortcut of path.h (path_final_query: the emitters tested one by one
// plus one occlusion ray, instead of a closest-hit query) as the GPU strategies take it:
// after a bounce only, so a path's first ray is always traced by the closest-hit query
// (the wavefront makes camera paths in place from their sample index). At depth 0 (a
// 0-bounce render) the GPU takes the closest hit instead: the same value.
template <class T>
PB_HD bool gpu_final_vertex(const SceneView& s, const PathConfig& c, const PathState<T>& st) {
  return st.depth > 0 && path_at_final_vertex(s, c, st);
}

// One path of (pixel, sample) in scalar type T (the traversal finds the hit triangle in
// float either way; surface_hit recomputes the hit in T), with the watertight or the
// Moeller-Trumbore triangle test, through the BVH layout kKind (traversal.h). Counts its
// bounce and shadow rays into n_bounce and n_shadow.
// The path's state st and its shadow query q live where the caller keeps them: in registers
// (trace_path_bvh below), or in the GPU block's shared memory (pixel.cu's parked state,
// which frees their registers while the traversals run).
template <uint32_t Kinds, class T, bool kWatertight, int kKind>
PB_HD Vec3f trace_path_bvh_in(const SceneView& s, const BvhView& bvh, const PathConfig& c, uint32_t pixel,
                              uint32_t sample, uint32_t& n_bounce, uint32_t& n_shadow, PathState<T>& st,
                              ShadowQuery<T>& q) {
  path_begin(s, c, pixel, sample, st);
  auto occlusion_test = [&](const ShadowQuery<T>& query) {  // query: q, filled just before
    ++n_shadow;
    if (!occluded<kWatertight, kKind>(bvh, Vec3f(query.ray.o), Vec3f(query.ray.d), 1.0f)) shadow_unoccluded(st, query);
  };
  for (;;) {
    if (gpu_final_vertex(s, c, st)) {  // only emitted light can still count
      if (path_final_query<Kinds>(s, c, st, q)) occlusion_test(q);
      break;
    }
    if (st.depth > 0) ++n_bounce;  // the camera ray is counted per path
    float t;
    const uint32_t prim = intersect_closest<kWatertight, kKind>(bvh, Vec3f(st.ray.o), Vec3f(st.ray.d), kInf, t);
    if (prim == kNoHit) break;
    bool wants_shadow;
    const PathEvent ev = path_hit<Kinds>(s, c, st, surface_hit(s, prim, st.ray), q, wants_shadow);
    if (wants_shadow) occlusion_test(q);
    if (ev == PathEvent::Done) break;
  }
  return Vec3f(st.L);
}

template <uint32_t Kinds, class T, bool kWatertight, int kKind>
PB_HD Vec3f trace_path_bvh(const SceneView& s, const BvhView& bvh, const PathConfig& c, uint32_t pixel,
                           uint32_t sample, uint32_t& n_bounce, uint32_t& n_shadow) {
  PathState<T> st;
  ShadowQuery<T> q;
  return trace_path_bvh_in<Kinds, T, kWatertight, kKind>(s, bvh, c, pixel, sample, n_bounce, n_shadow, st, q);
}

}  // namespace pb::bvh
