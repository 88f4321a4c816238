#include "pathbench/bvh/bvh_layout.h"

#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <string>

#include "pathbench/common/errors.h"
#include "pathbench/common/report.h"

namespace pb::bvh {

namespace {
constexpr struct {
  GpuBvhLayout layout;
  const char* name;
} kNames[] = {{GpuBvhLayout::Auto, "auto"},   {GpuBvhLayout::Binary, "binary"}, {GpuBvhLayout::Wide4, "wide4"},
              {GpuBvhLayout::Wide8, "wide8"}, {GpuBvhLayout::Brute, "brute"},   {GpuBvhLayout::Leaves, "leaves"},
              {GpuBvhLayout::Rects, "rects"}, {GpuBvhLayout::RectsBinary, "rects-binary"}};

// The binary BVH's leaves in depth-first order, each with the box its parent node holds
// for it (padded by the builder), for the leaves layout.
std::vector<LeafBox> leaf_boxes(const BvhHost& bvh) {
  std::vector<LeafBox> out;
  std::vector<uint32_t> stack;
  if (!bvh.nodes.empty()) stack.push_back(0);
  while (!stack.empty()) {
    const BvhNode& n = bvh.nodes[stack.back()];
    stack.pop_back();
    for (int c = 1; c >= 0; --c) {  // child 0 ends up on top: visited first
      if (!is_leaf(n.child[c])) {
        stack.push_back(n.child[c]);
        continue;
      }
      if (n.x[2 * c] > n.x[2 * c + 1]) continue;  // the empty box beside a one-leaf scene (bvh_build.cpp)
      LeafBox l{};
      l.lo[0] = n.x[2 * c]; l.hi[0] = n.x[2 * c + 1];
      l.lo[1] = n.y[2 * c]; l.hi[1] = n.y[2 * c + 1];
      l.lo[2] = n.z[2 * c]; l.hi[2] = n.z[2 * c + 1];
      l.ref = n.child[c];
      out.push_back(l);
    }
  }
  return out;
}
}  // namespace

const char* to_string(GpuBvhLayout l) {
  if (l == GpuBvhLayout::TwoLevel) return "two-level";  // chosen by --instancing, not by name
  for (const auto& n : kNames)
    if (n.layout == l) return n.name;
  return "?";
}

GpuBvhLayout parse_gpu_bvh_layout(std::string_view name, std::string_view what) {
  for (const auto& n : kNames)
    if (name == n.name) return n.layout;
  throw InputError(fmt::format("{}: '{}' is not a GPU BVH layout (auto, binary, wide4, wide8, brute, leaves, rects, rects-binary)", what, name));
}

GpuBvhOptions GpuBvhOptions::from_env(Instancing instancing) {
  GpuBvhOptions o;
  o.instancing = instancing;
  if (const char* v = std::getenv("PATHBENCH_GPU_BVH"); v && *v) o.layout = parse_gpu_bvh_layout(v);
  if (const char* v = std::getenv("PATHBENCH_GPU_BRUTE_MAX_TRIS"); v && *v) {
    const std::string_view s(v);
    uint32_t n = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), n);
    if (ec != std::errc() || end != s.data() + s.size() || n > kBruteMaxTrianglesLimit)
      throw InputError(fmt::format("PATHBENCH_GPU_BRUTE_MAX_TRIS: '{}' is not a triangle count 0..{}", s,
                                   kBruteMaxTrianglesLimit));
    o.brute_max_triangles = n;
  }
  return o;
}

GpuBvhLayout resolve_layout(const GpuBvhOptions& o, size_t triangles, size_t instances) {
  if (use_instancing(o.instancing, instances)) return GpuBvhLayout::TwoLevel;
  if (o.layout != GpuBvhLayout::Auto) return o.layout;
  if (triangles <= o.brute_max_triangles) return GpuBvhLayout::Brute;
  return triangles <= kLeavesAutoMaxTriangles && instances == 0 ? GpuBvhLayout::Leaves : kAutoLayout;
}

namespace {
// rects-binary (rects_binary.h), asked for by name: a scene it cannot trace is an InputError.
void build_rects_binary(const Scene& scene, SceneBvhHost& out) {
  if (!scene.instances.empty())
    throw InputError(fmt::format("GPU BVH layout rects-binary: scene '{}' has instances, whose ties it does not order "
                                 "(binary, wide4, wide8, brute or --instancing do)", scene.name));
  std::vector<char> in_rect;
  largest_axis_rects(scene, kRectsBinaryMaxRects, out.rects, out.rect_groups, in_rect);
  const size_t walls = 2 * out.rects.size();
  if (walls == 0)
    throw InputError(fmt::format("GPU BVH layout rects-binary: scene '{}' has no two triangles that make an "
                                 "axis-aligned rectangle (binary suits it)", scene.name));
  if (walls == scene.triangles.size())
    throw InputError(fmt::format("GPU BVH layout rects-binary: every triangle of scene '{}' is half of an "
                                 "axis-aligned rectangle (rects suits it)", scene.name));
  out.binary = build_bvh(scene, BvhBuildOptions{}.with_env(), &in_rect);
  out.binary_depth = out.binary.depth;
  out.binary_leaves = out.binary.leaves;
  out.binary_sah = out.binary.sah_cost;
  // The rectangles' triangles after the BVH's, for Moeller-Trumbore (rects_binary.h).
  for (const AxisRect& r : out.rects)
    for (uint32_t id : {r.key, r.other & kRectIdMask}) out.binary.tris.push_back(bvh_triangle(scene, id));
  out.rect_tris = uint32_t(walls);
}
}  // namespace

SceneBvhHost build_scene_bvh(const Scene& scene, const GpuBvhOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  SceneBvhHost out;
  out.layout = resolve_layout(options, scene.triangles.size(), scene.instances.size());
  if (out.layout == GpuBvhLayout::TwoLevel) {
    out.two_level = build_two_level_bvh(scene);
  } else if (out.layout == GpuBvhLayout::Brute) {
    out.all.reserve(scene.triangles.size());
    for (uint32_t i = 0; i < scene.triangles.size(); ++i) out.all.push_back(bvh_triangle(scene, i));
  } else if (out.layout == GpuBvhLayout::RectsBinary) {
    build_rects_binary(scene, out);
  }
  if (out.layout != GpuBvhLayout::TwoLevel && out.layout != GpuBvhLayout::Brute &&
      out.layout != GpuBvhLayout::RectsBinary) {
    // auto: where it takes leaves and every triangle pairs into an axis-aligned rectangle
    // (paper-cornell), the rectangles.
    if (out.layout == GpuBvhLayout::Leaves && options.layout == GpuBvhLayout::Auto &&
        build_axis_rects(scene, out.rects, out.rect_groups))
      out.layout = GpuBvhLayout::Rects;
    // The rects layout keeps the leaves layout too (a few boxes and the triangles): what
    // --no-watertight's triangle test (Moeller-Trumbore, the accuracy study's) traces, as the
    // rectangles are a watertight test. Both test every leaf or rectangle for every ray.
    const bool rects = out.layout == GpuBvhLayout::Rects, leaves = rects || out.layout == GpuBvhLayout::Leaves;
    const char* name = to_string(out.layout);
    if (leaves && !scene.instances.empty())
      throw InputError(fmt::format("GPU BVH layout {}: scene '{}' has instances, whose ties the {} traversal does "
                                   "not order (binary, wide4, wide8, brute or --instancing do)", name, scene.name, name));
    if (leaves && scene.triangles.size() > kLeavesMaxTriangles)
      throw InputError(fmt::format("GPU BVH layout {}: scene '{}' has {} triangles; it tests every {} for "
                                   "every ray and takes at most {} (binary suits it)", name, scene.name,
                                   scene.triangles.size(), rects ? "rectangle" : "leaf's box", kLeavesMaxTriangles));
    std::string why;
    if (rects && out.rects.empty() && !build_axis_rects(scene, out.rects, out.rect_groups, &why))
      throw InputError(fmt::format("GPU BVH layout rects: scene '{}': {} (leaves or binary suit it)", scene.name, why));
    const bool wide = out.layout == GpuBvhLayout::Wide4 || out.layout == GpuBvhLayout::Wide8;
    BvhBuildOptions bo = BvhBuildOptions{}.with_env();  // the environment's build overrides (measurements)
    if (wide) bo.max_leaf_size = kWideMaxLeafTris;  // a wide leaf holds up to 3
    out.binary = build_bvh(scene, bo);
    if (!rects) {  // the BVH it traces (rects: the rectangles, as nodes() and the report say)
      out.binary_depth = out.binary.depth;
      out.binary_leaves = out.binary.leaves;
      out.binary_sah = out.binary.sah_cost;
    }
    if (wide) {
      out.wide = collapse_bvh(out.binary, out.layout == GpuBvhLayout::Wide4 ? 4 : 8);
      out.binary = BvhHost{};
    }
    if (leaves) {
      out.leaves = leaf_boxes(out.binary);
      out.binary.nodes.clear();  // the triangles stay, in leaf order
    }
  }
  out.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.exact_ties = !scene.instances.empty();
  return out;
}

BvhView SceneBvhHost::view() const {
  BvhView v;
  switch (layout) {
    case GpuBvhLayout::Brute:
      v.kind = TraversalKind::AllTriangles;
      v.tris = all.data();
      v.num_tris = uint32_t(all.size());
      break;
    case GpuBvhLayout::Wide4:
    case GpuBvhLayout::Wide8:
      v.kind = TraversalKind::Wide;
      v.wide = wide.view();
      break;
    case GpuBvhLayout::TwoLevel:
      v.kind = TraversalKind::TwoLevel;
      v.two_level = two_level.view();
      break;
    case GpuBvhLayout::Leaves:
      v.kind = TraversalKind::Leaves;
      v.leaves = {leaves.data(), binary.tris.data(), uint32_t(leaves.size()), uint32_t(binary.tris.size())};
      break;
    case GpuBvhLayout::Rects:  // kernels of their own (TraversalKind::Rects); the leaves for Moeller-Trumbore
      v.kind = TraversalKind::Rects;
      v.leaves = {leaves.data(), binary.tris.data(), uint32_t(leaves.size()), uint32_t(binary.tris.size())};
      v.leaves.rects = rects.data();
      v.leaves.rect_groups = rect_groups;
      break;
    case GpuBvhLayout::RectsBinary: {
      v.kind = TraversalKind::RectsBinary;
      BinaryBvhView rest = binary.view();
      rest.num_tris -= rect_tris;
      v.rects_binary = {rest, rects.data(), rect_groups, binary.tris.data() + rest.num_tris, rect_tris};
      break;
    }
    default:
      v.kind = TraversalKind::Binary;
      v.binary = binary.view();
  }
  v.binary.exact_ties = v.wide.exact_ties = v.leaves.exact_ties = v.exact_ties = exact_ties ? 1u : 0u;
  return v;
}

uint64_t SceneBvhHost::bytes() const {
  return binary.bytes() + wide.bytes() + all.size() * sizeof(BvhTriangle) + leaves.size() * sizeof(LeafBox) +
         rects.size() * sizeof(AxisRect) + two_level.bytes();
}
uint32_t SceneBvhHost::nodes() const {
  if (layout == GpuBvhLayout::Rects) return uint32_t(rects.size());  // its leaves serve Moeller-Trumbore only
  return uint32_t(binary.nodes.size() + wide.nodes.size() + leaves.size() + two_level.top_nodes.size() +
                  two_level.bottom_nodes.size());
}
uint32_t SceneBvhHost::node_bytes() const {
  if (layout == GpuBvhLayout::Brute) return 0;
  if (layout == GpuBvhLayout::Leaves) return uint32_t(sizeof(LeafBox));
  if (layout == GpuBvhLayout::Rects) return uint32_t(sizeof(AxisRect));
  return layout == GpuBvhLayout::Binary || layout == GpuBvhLayout::TwoLevel || layout == GpuBvhLayout::RectsBinary
             ? uint32_t(sizeof(BvhNode))
             : uint32_t(sizeof(WideNode));
}

nlohmann::json instancing_report(const Scene& scene, const SceneBvhHost& bvh, Instancing asked) {
  const bool used = bvh.layout == GpuBvhLayout::TwoLevel;
  const TwoLevelHost& t = bvh.two_level;
  const char* why = used                     ? "a two-level BVH over the scene's instances"
                    : scene.instances.empty() ? "the scene has no instances: traced flat"
                                              : "asked off: traced flat";
  return InstancingSummary{asked, used, why, scene.instances.size(), scene.prototypes.size(), t.instanced,
                           t.prototypes, t.instances_left_flat, used ? t.flat_triangles : scene.triangles.size(),
                           bvh.bytes(), bvh.build_seconds}
      .to_json();
}

}  // namespace pb::bvh
