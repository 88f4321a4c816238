#pragma once
// The shared path step (common/path.h) as both GPU strategies drive it: the last-vertex
// shortcut they take alike, so the pixel megakernel and the wavefront stages trace the
// same rays and give the same film.
#include <limits>

#include "pathbench/common/path.h"

namespace pb::gpu {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The last-vertex shortcut of path.h (path_final_query: the emitters tested one by one
// plus one occlusion ray, instead of a closest-hit query) on the GPU: used after a
// bounce only, so a path's first ray is always traced by the closest-hit kernel (the
// wavefront makes camera paths in place from their sample index). At depth 0 (a
// 0-bounce render) both GPU strategies take the closest hit instead: the same value.
template <class T>
__device__ __forceinline__ bool gpu_final_vertex(const SceneView& s, const PathConfig& c, const PathState<T>& st) {
  return st.depth > 0 && path_at_final_vertex(s, c, st);
}

}  // namespace pb::gpu
