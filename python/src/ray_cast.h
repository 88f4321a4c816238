#pragma once
// Batched ray casts for the Python module: the same rays through the CPU tracer's
// Embree scene or through the GPU BVH's traversal (the host+device function of
// gpu/bvh.h, run here on the host), in parallel with TBB. Plain C++ on raw arrays:
// the bindings hand in numpy buffers and release the GIL around these calls.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene_handle.h"

namespace pb::python {

enum class Backend { Embree, Bvh };
Backend parse_backend(std::string_view name);  // "embree" | "bvh"; InputError otherwise

// n rays, row-major (n, 3) origins and directions; tnear / tfar per ray (stride 1) or
// one value for all (stride 0). Directions need not be unit length: t is in units of
// the direction's length, as in Embree.
struct RayBatch {
  const float* origins = nullptr;
  const float* directions = nullptr;
  const float* tnear = nullptr;
  const float* tfar = nullptr;
  size_t tnear_stride = 0, tfar_stride = 0;
  size_t n = 0;
  float tnear_at(size_t i) const { return tnear[i * tnear_stride]; }
  float tfar_at(size_t i) const { return tfar[i * tfar_stride]; }
};

// Throws InputError naming the first offending ray: a non-finite origin or direction,
// a zero direction, tnear negative or not finite, tfar NaN or below tnear; and, for
// the BVH backend, tnear other than 0 (its traversal tests t_min < t < tfar, watertight.h) or
// watertight = false (its triangle test is always watertight).
void validate(const RayBatch& rays, Backend backend, bool watertight);

// Closest hits: hit[i], prim[i] (scene triangle id, 0xFFFFFFFF on a miss) and t[i]
// (infinity on a miss). Validates first.
void intersect(const SceneHandle& scene, const RayBatch& rays, Backend backend, bool watertight, bool* hit,
               uint32_t* prim, float* t);

// Any hit in (tnear, tfar): occluded[i]. Validates first.
void occluded(const SceneHandle& scene, const RayBatch& rays, Backend backend, bool watertight, bool* occluded);

}  // namespace pb::python
