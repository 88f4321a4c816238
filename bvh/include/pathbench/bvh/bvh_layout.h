#pragma once
// Which acceleration structure the GPU traces against, and its host-side build:
//   binary  the binary BVH (binary_bvh.h), 64-byte nodes;
//   wide4 / wide8  the compressed wide BVH (wide_bvh.h), 80-byte nodes of <= 4 / 8 children;
//   brute   no BVH: every triangle tested (brute_force.h), for tiny scenes;
//   leaves  the binary BVH's leaves, each with its box, and no inner nodes
//           (leaf_list.h), for tiny scenes without instances;
//   rects   the scene as axis-aligned rectangles (axis_plane.h: every triangle half of
//           one), each tested as a flat box, no triangle test (TraversalKind::Rects,
//           its arrays in LeafListView::rects);
//   rects-binary  the scene's largest axis-aligned rectangles (up to kRectsBinaryMaxRects:
//           a room's walls) as rects, the other triangles in a binary BVH, the rectangles
//           tested first (rects_binary.h, TraversalKind::RectsBinary);
//   auto    brute at most `brute_max_triangles` triangles, else leaves up to
//           kLeavesAutoMaxTriangles (a scene without instances) -- rects where every
//           triangle pairs into an axis-aligned rectangle --, else kAutoLayout (rects-binary
//           only by name: measured, below);
//   two-level  the instanced scene's (two_level_bvh.h): not asked for by name but by
//           GpuBvhOptions::instancing (--instancing), on a scene with instances.
// The choice comes from GpuBvhOptions (GpuScene's constructor: one process can A/B
// them), by default from the environment: PATHBENCH_GPU_BVH=<name>,
// PATHBENCH_GPU_BRUTE_MAX_TRIS=<n>. Plain C++ (tests build it without CUDA).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "pathbench/bvh/bvh_build.h"
#include "pathbench/bvh/traversal.h"
#include "pathbench/bvh/two_level_build.h"
#include "pathbench/bvh/wide_bvh_build.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"

namespace pb::bvh {

enum class GpuBvhLayout : uint32_t {
  Auto = 0, Binary = 1, Wide4 = 2, Wide8 = 3, Brute = 4, TwoLevel = 5, Leaves = 6, Rects = 7, RectsBinary = 8
};

// Measured on an H100 (results/nvidia-h100-80gb-hbm3/archive/layouts-a12fc4c, interleaved,
// CUDA events; before the leaves layout existed): the binary BVH is the fastest everywhere we measured — paper-cornell
// 256x256x800 pixel 13.7 ms (wide8 19.7, wide4 38.2, brute 18.4), wavefront 19.2 ms
// (wide8 21.5, brute 25.5); ico:8 pixel 75.8 ms (wide8 114.2, wide4 147.3); brute force
// never beat it, so auto means binary and brute force is off unless asked for.
// Measured again for issue 32 with the wide megakernel at its own occupancy (5 blocks; the
// plain stack: a short stack in registers was slower), H100, 256x256x800 nee, interleaved
// (results/nvidia-h100-80gb-hbm3/archive/wide-bvh-eed5258): wide8 loses everywhere, from
// 1.3 k to 13.3 M triangles: ico:8 43.03 ms binary against 92.15 wide8, the suite's
// bunny-armadillo 44.92 / 111.86, glass-dragon 200.66 / 471.56, large-mesh 55.08 / 131.26.
// The rule stays: leaves up to kLeavesAutoMaxTriangles (no instances), two-level where
// --instancing says so, else binary; wide4 / wide8 only by name.
constexpr GpuBvhLayout kAutoLayout = GpuBvhLayout::Binary;
constexpr uint32_t kDefaultBruteMaxTriangles = 0;
constexpr uint32_t kBruteMaxTrianglesLimit = 1u << 16;  // beyond that brute force is never the answer
// auto's leaves layout: up to this many triangles (a scene without instances). Measured on
// an H100 at 597d689 (results/nvidia-h100-80gb-hbm3/archive/leaves-597d689, 256x256x800 nee pixel,
// interleaved): paper-cornell (14 triangles, 7 leaves) 11.54 -> 11.34 ms, wavefront 15.60
// -> 15.29; paper-cornell-ico:0 (34) 20.63 -> 20.57; ico:1 (94) 23.49 -> 32.30: every box is
// tested for every ray, so it pays only while the leaves are few.
constexpr uint32_t kLeavesAutoMaxTriangles = 32;
// Where auto would take leaves and every triangle pairs into an axis-aligned rectangle
// (build_axis_rects), it takes rects. Measured on an H100 at f37e775
// (results/nvidia-h100-80gb-hbm3/archive/rects-f37e775, 256x256x800 nee, interleaved against
// main 2232aee's leaves): paper-cornell pixel 10.19 -> 7.42 ms, wavefront 13.57 -> 12.63,
// paper-queue 15.49 -> 14.14; raw incoherent closest hits 27.6 -> 49.7 G rays/s.
// The leaves layout tests every leaf's box for every ray: asked for by name, up to this many.
constexpr uint32_t kLeavesMaxTriangles = 1u << 16;
// rects-binary: the rectangles every ray tests before the binary BVH of the rest, the
// largest by area (a room's 6 walls and its light are 7). Host counts, 200,000 random rays
// from inside the box: paper-cornell-ico:8 binary 9.94 nodes and 2.26 triangles a closest
// hit, rects-binary 7 rectangles, then 4.92 nodes and 0.41 triangles. Measured on an H100
// (docs/notes/gpu-log.md, "Walls first"; 256x256x800 nee, interleaved against binary), it
// pays only where traversal is memory bound: the wavefront's ico:8 51.38 -> 46.26 ms (0.90),
// while the megakernel, whose warps wait for their slowest lane's traversal, does not gain
// (ico:8 40.48 -> 40.57 ms, bunny-armadillo 41.58 -> 42.33, glass-dragon 195.1 -> 200.8,
// large-mesh 52.96 -> 54.15, ico:3 25.80 -> 29.79). So auto does not take it.
constexpr uint32_t kRectsBinaryMaxRects = 16;

struct GpuBvhOptions {
  GpuBvhLayout layout = GpuBvhLayout::Auto;
  uint32_t brute_max_triangles = kDefaultBruteMaxTriangles;  // auto: brute force up to this many
  // The render's --instancing: where use_instancing() says so, the two-level BVH
  // whatever `layout` says.
  Instancing instancing = Instancing::Off;
  // From PATHBENCH_GPU_BVH and PATHBENCH_GPU_BRUTE_MAX_TRIS where set, with the render's
  // --instancing; throws InputError naming the variable for a value it cannot use.
  static GpuBvhOptions from_env(Instancing instancing = Instancing::Off);
};

const char* to_string(GpuBvhLayout l);
// Throws InputError naming `what` (the option or variable) for an unknown name.
GpuBvhLayout parse_gpu_bvh_layout(std::string_view name, std::string_view what = "PATHBENCH_GPU_BVH");
// `auto` resolved for a scene of `triangles` triangles and `instances` instances; other
// layouts are kept (but for instancing, above).
GpuBvhLayout resolve_layout(const GpuBvhOptions& o, size_t triangles, size_t instances = 0);

// The structure built for one layout, ready to upload (only the layout's arrays are filled).
struct SceneBvhHost {
  GpuBvhLayout layout = GpuBvhLayout::Binary;  // resolved, never Auto
  BvhHost binary;                  // Binary
  WideBvhHost wide;                // Wide4, Wide8
  std::vector<BvhTriangle> all;    // Brute: the triangles in scene order
  std::vector<LeafBox> leaves;    // Leaves: the leaves of `binary`, whose triangles it keeps (no nodes)
  std::vector<AxisRect> rects;    // Rects, RectsBinary: the rectangles, grouped by plane axis (rect_groups)
  RectGroups rect_groups;
  // RectsBinary: `binary` is the BVH of the triangles not in a rectangle; the rectangles'
  // triangles follow its own in binary.tris, rect_tris of them (what --no-watertight's
  // Moeller-Trumbore test traces instead of the rectangles).
  uint32_t rect_tris = 0;
  TwoLevelHost two_level;          // TwoLevel
  uint32_t binary_depth = 0, binary_leaves = 0;  // the binary BVH the wide one came from
  double binary_sah = 0, build_seconds = 0;
  // The scene has instances: every traversal of it keeps the least (t, id) (hit_tests.h), so that
  // its flat and two-level answers agree; set by build_scene_bvh, carried by view().
  bool exact_ties = false;

  BvhView view() const;  // host pointers
  uint64_t bytes() const;
  uint32_t nodes() const;
  uint32_t node_bytes() const;  // one node's size (0 for brute force; leaves: a box)
};

SceneBvhHost build_scene_bvh(const Scene& scene, const GpuBvhOptions& options);

// The scene's triangles paired into axis-aligned rectangles (axis_plane.h), each pair's
// four corners exactly {u0, u1} x {v0, v1} in one plane k = c, grouped by k and within a
// group by lower triangle id. False (and `why` says which triangle) where a triangle is
// not half of such a rectangle.
bool build_axis_rects(const Scene& scene, std::vector<AxisRect>& rects, RectGroups& groups, std::string* why = nullptr);

// The scene's largest axis-aligned rectangles, at most `max_rects` (pairs of triangles as
// build_axis_rects pairs them; the others are left out), grouped as build_axis_rects
// groups them; `in_rect[i]` says whether triangle i is half of one kept. Linear in the
// scene's triangles (pairs are found by their common box). Returns the share of the scene
// box's surface the kept rectangles cover (0 where there are none).
double largest_axis_rects(const Scene& scene, uint32_t max_rects, std::vector<AxisRect>& rects, RectGroups& groups,
                          std::vector<char>& in_rect);

// What a report says of --instancing for the structure `bvh` built for `scene`: asked, used,
// why, instances and prototypes (the scene's and those built), triangles left flat, the
// structure's bytes and build time (report.extra["instancing"], GPU and HostGpuTracer).
nlohmann::json instancing_report(const Scene& scene, const SceneBvhHost& bvh, Instancing asked);

}  // namespace pb::bvh
