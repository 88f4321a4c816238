#pragma once
// Which acceleration structure the GPU traces against, and its host-side build:
//   binary  the binary BVH (bvh.h), 64-byte nodes;
//   wide4 / wide8  the compressed wide BVH (wide_bvh.h), 80-byte nodes of <= 4 / 8 children;
//   brute   no BVH: every triangle tested (brute_force.h), for tiny scenes;
//   auto    brute at most `brute_max_triangles` triangles, else kAutoLayout.
// The choice comes from GpuBvhOptions (GpuScene's constructor: one process can A/B
// them), by default from the environment: PATHBENCH_GPU_BVH=<name>,
// PATHBENCH_GPU_BRUTE_MAX_TRIS=<n>. Plain C++ (tests build it without CUDA).
#include <cstdint>
#include <string_view>
#include <vector>

#include "pathbench/common/scene.h"
#include "pathbench/gpu/bvh_build.h"
#include "pathbench/gpu/traversal.h"
#include "pathbench/gpu/wide_bvh_build.h"

namespace pb::gpu {

enum class GpuBvhLayout : uint32_t { Auto = 0, Binary = 1, Wide4 = 2, Wide8 = 3, Brute = 4 };

// Defaults of `auto`, to be set from the device measurements (gpu/NOTES.md,
// "Traversal layouts"; `gpu/run_on_device.sh layouts` measures them). Until then, by
// instruction counts: one wide8 node holds a scene of up to 24 triangles, and a shadow
// ray through the empty box tests none of them there but every one under brute force.
constexpr GpuBvhLayout kAutoLayout = GpuBvhLayout::Wide8;
constexpr uint32_t kDefaultBruteMaxTriangles = 8;
constexpr uint32_t kBruteMaxTrianglesLimit = 1u << 16;  // beyond that brute force is never the answer

struct GpuBvhOptions {
  GpuBvhLayout layout = GpuBvhLayout::Auto;
  uint32_t brute_max_triangles = kDefaultBruteMaxTriangles;  // auto: brute force up to this many
  // From PATHBENCH_GPU_BVH and PATHBENCH_GPU_BRUTE_MAX_TRIS where set; throws InputError
  // naming the variable for a value it cannot use.
  static GpuBvhOptions from_env();
};

const char* to_string(GpuBvhLayout l);
// Throws InputError naming `what` (the option or variable) for an unknown name.
GpuBvhLayout parse_gpu_bvh_layout(std::string_view name, std::string_view what = "PATHBENCH_GPU_BVH");
// `auto` resolved for a scene of `triangles` triangles; other layouts are kept.
GpuBvhLayout resolve_layout(const GpuBvhOptions& o, size_t triangles);

// The structure built for one layout, ready to upload (only the layout's arrays are filled).
struct SceneBvhHost {
  GpuBvhLayout layout = GpuBvhLayout::Binary;  // resolved, never Auto
  BvhHost binary;                  // Binary
  WideBvhHost wide;                // Wide4, Wide8
  std::vector<BvhTriangle> all;    // Brute: the triangles in scene order
  uint32_t binary_depth = 0, binary_leaves = 0;  // the binary BVH the wide one came from
  double binary_sah = 0, build_seconds = 0;

  BvhView view() const;  // host pointers
  uint64_t bytes() const;
  uint32_t nodes() const;
  uint32_t node_bytes() const;  // one node's size (0 for brute force)
};

SceneBvhHost build_scene_bvh(const Scene& scene, const GpuBvhOptions& options);

}  // namespace pb::gpu
