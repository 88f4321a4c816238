#include "pathbench/bvh/bvh_build.h"

#include <embree3/rtcore.h>
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <type_traits>

#include "pathbench/common/errors.h"
#include "build_box.h"

namespace pb::bvh {

namespace {

// Builder-side nodes, allocated by Embree's thread-local allocator and released with
// the RTCBVH.
struct BuildNode {
  uint32_t leaf;  // 0
  uint32_t child_count;
  void* child[2];
  RTCBounds bounds[2];
};
struct BuildLeaf {
  uint32_t leaf;  // 1
  uint32_t count;
  float lo[3], hi[3];  // the union of the primitives' bounds as Embree gave them (clipped by spatial splits)
  uint32_t prims[1];  // really `count`
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned child_count, void*) {
  auto* n = static_cast<BuildNode*>(rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16));
  n->leaf = 0;
  n->child_count = child_count;
  n->child[0] = n->child[1] = nullptr;
  return n;
}

void set_children(void* node, void** children, unsigned count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->child[i] = children[i];
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count && i < 2; ++i) n->bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
  auto* l = static_cast<BuildLeaf*>(
      rtcThreadLocalAlloc(alloc, sizeof(BuildLeaf) + sizeof(uint32_t) * (count ? count - 1 : 0), 16));
  l->leaf = 1;
  l->count = uint32_t(count);
  for (int k = 0; k < 3; ++k) {
    l->lo[k] = std::numeric_limits<float>::infinity();
    l->hi[k] = -std::numeric_limits<float>::infinity();
  }
  for (size_t i = 0; i < count; ++i) {
    l->prims[i] = prims[i].primID;
    const RTCBuildPrimitive& p = prims[i];
    const float lo[3] = {p.lower_x, p.lower_y, p.lower_z}, hi[3] = {p.upper_x, p.upper_y, p.upper_z};
    for (int k = 0; k < 3; ++k) {
      l->lo[k] = std::min(l->lo[k], lo[k]);
      l->hi[k] = std::max(l->hi[k], hi[k]);
    }
  }
  return l;
}

using Box = BuildBox;

class Flattener {
 public:
  Flattener(const Scene& s, const BvhBuildOptions& o, BvhHost& out, float pad) : s_(s), o_(o), out_(out), pad_(pad) {}

  Box tri_box(uint32_t prim) const {
    Box b;
    for (int k = 0; k < 3; ++k) b.grow(s_.positions[s_.triangles[prim].v[k]]);
    return b;
  }

  // Emits `prims` as one leaf if they fit, else as a balanced subtree of leaves. `clip`:
  // the bounds Embree gave the leaf's references. A spatial split (high_quality) clips a
  // reference's bounds at the split plane; the leaf's box is then its triangles' boxes cut
  // to those bounds, which still holds every point of a triangle that this reference
  // stands for (the references of one triangle tile its box). Without splits the bounds are
  // the triangles' boxes, computed alike, and the cut changes nothing.
  uint32_t emit_prims(const uint32_t* prims, uint32_t count, Box& box, uint32_t depth, const Box& clip) {
    if (count <= o_.max_leaf_size || count <= kMaxLeafPrims) {
      if (count > kMaxLeafPrims) throw std::logic_error("bvh: leaf too large");
      const uint32_t first = uint32_t(out_.tris.size());
      if (first + count > kLeafFirstMask) throw std::runtime_error("bvh: too many triangle references for the GPU layout");
      for (uint32_t i = 0; i < count; ++i) {
        const uint32_t p = prims[i];
        out_.tris.push_back(bvh_triangle(s_, p));
        const Box tb = tri_box(p);
        box.grow(tb.lo);
        box.grow(tb.hi);
      }
      box.lo = vmax(box.lo, clip.lo);
      box.hi = vmin(box.hi, clip.hi);
      ++out_.leaves;
      out_.depth = std::max(out_.depth, depth);
      leaf_cost_ += box.area() * o_.intersection_cost * count;
      return make_leaf_ref(first, count);
    }
    // Oversized leaf (Embree hit its depth limit): split in two halves.
    const uint32_t idx = alloc_node();
    Box b0, b1;
    const uint32_t half = count / 2;
    const uint32_t r0 = emit_prims(prims, half, b0, depth + 1, clip);
    const uint32_t r1 = emit_prims(prims + half, count - half, b1, depth + 1, clip);
    finish_node(idx, r0, b0, r1, b1);
    box.grow(b0.lo); box.grow(b0.hi); box.grow(b1.lo); box.grow(b1.hi);
    return idx;
  }

  uint32_t emit(const void* p, Box& box, uint32_t depth) {
    if (static_cast<const BuildLeaf*>(p)->leaf) {
      const auto* l = static_cast<const BuildLeaf*>(p);
      Box clip;
      clip.lo = {l->lo[0], l->lo[1], l->lo[2]};
      clip.hi = {l->hi[0], l->hi[1], l->hi[2]};
      return emit_prims(l->prims, l->count, box, depth, clip);
    }
    const auto* n = static_cast<const BuildNode*>(p);
    const uint32_t idx = alloc_node();
    Box b[2];
    uint32_t r[2] = {0, 0};
    for (int c = 0; c < 2; ++c) {
      if (c < int(n->child_count) && n->child[c]) r[c] = emit(n->child[c], b[c], depth + 1);
      else r[c] = make_leaf_ref(0, 1);  // never entered: its box is empty
    }
    finish_node(idx, r[0], b[0], r[1], b[1]);
    for (int c = 0; c < 2; ++c)
      if (!b[c].empty()) { box.grow(b[c].lo); box.grow(b[c].hi); }
    return idx;
  }

  uint32_t alloc_node() {
    out_.nodes.push_back(BvhNode{});
    return uint32_t(out_.nodes.size() - 1);
  }

  void finish_node(uint32_t idx, uint32_t r0, const Box& b0, uint32_t r1, const Box& b1) {
    BvhNode& n = out_.nodes[idx];
    const Box* b[2] = {&b0, &b1};
    for (int c = 0; c < 2; ++c) {
      Box s = *b[c];
      if (s.empty()) {
        // A box at +infinity: every slab distance is +-inf, so tn > tf for any ray.
        const float inf = std::numeric_limits<float>::infinity();
        s.lo = {inf, inf, inf};
        s.hi = {inf, inf, inf};
      } else {
        s.lo = s.lo - Vec3f{pad_, pad_, pad_};
        s.hi = s.hi + Vec3f{pad_, pad_, pad_};
      }
      set_slot_box(n, c, s);
    }
    n.child[0] = r0;
    n.child[1] = r1;
    Box u = b0;
    if (!b1.empty()) { u.grow(b1.lo); u.grow(b1.hi); }
    inner_cost_ += u.area() * o_.traversal_cost;
  }

  double inner_cost_ = 0, leaf_cost_ = 0;

 private:
  const Scene& s_;
  const BvhBuildOptions& o_;
  BvhHost& out_;
  float pad_;
};

void on_embree_error(void*, RTCError code, const char* str) {
  fmt::print(stderr, "embree (BVH builder) error {}: {}\n", int(code), str ? str : "");
}

}  // namespace

BvhBuildOptions BvhBuildOptions::with_env() const {
  BvhBuildOptions o = *this;
  const auto number = [](const char* name, double lo, double hi, auto& value) {  // an integer where value is one
    const char* v = std::getenv(name);
    if (!v || !*v) return;
    char* end = nullptr;
    const double x = std::strtod(v, &end);
    const bool integral = std::is_integral_v<std::remove_reference_t<decltype(value)>>;
    if (end == v || *end != '\0' || !(x >= lo && x <= hi) || (integral && x != std::floor(x)))
      throw InputError(fmt::format("{}: '{}' is not a number in [{}, {}]", name, v, lo, hi));
    value = static_cast<std::remove_reference_t<decltype(value)>>(x);
  };
  number("PATHBENCH_GPU_BVH_LEAF_SIZE", 1, kMaxLeafPrims, o.max_leaf_size);
  number("PATHBENCH_GPU_BVH_TRAVERSAL_COST", 1e-3, 1e3, o.traversal_cost);
  number("PATHBENCH_GPU_BVH_INTERSECTION_COST", 1e-3, 1e3, o.intersection_cost);
  number("PATHBENCH_GPU_BVH_OPTIMIZE", 0, 8, o.optimize_passes);
  if (const char* v = std::getenv("PATHBENCH_GPU_BVH_QUALITY"); v && *v) {
    const std::string_view q(v);
    if (q != "medium" && q != "high")
      throw InputError(fmt::format("PATHBENCH_GPU_BVH_QUALITY: '{}' is not medium or high", q));
    o.high_quality = q == "high";
  }
  return o;
}

BvhTriangle bvh_triangle(const Scene& scene, uint32_t id) {
  const Triangle& t = scene.triangles[id];
  const Vec3f a = scene.positions[t.v[0]], b = scene.positions[t.v[1]], c = scene.positions[t.v[2]];
  BvhTriangle bt{};
  bt.v0[0] = a.x; bt.v0[1] = a.y; bt.v0[2] = a.z; bt.prim = id;
  bt.v1[0] = b.x; bt.v1[1] = b.y; bt.v1[2] = b.z;
  bt.v2[0] = c.x; bt.v2[1] = c.y; bt.v2[2] = c.z;
  return bt;
}

BvhHost build_bvh(const Scene& scene, const BvhBuildOptions& options, const std::vector<char>* leave_out) {
  if (options.max_leaf_size < 1 || options.max_leaf_size > kMaxLeafPrims)
    throw std::invalid_argument(fmt::format("bvh: max_leaf_size must be 1..{}", kMaxLeafPrims));
  const auto t0 = std::chrono::steady_clock::now();
  BvhHost out;
  // The scene triangles in the BVH: all of them (ids left empty), or those not left out.
  std::vector<uint32_t> ids;
  if (leave_out)
    for (uint32_t i = 0; i < scene.triangles.size(); ++i)
      if (!(*leave_out)[i]) ids.push_back(i);
  const size_t n = leave_out ? ids.size() : scene.triangles.size();
  auto id_of = [&](size_t i) { return leave_out ? ids[i] : uint32_t(i); };

  // Pad boxes by a few ulps of the scene's largest coordinate: the slab test's
  // rounding (fused or not) then never culls a box a ray really touches.
  float max_coord = 0;
  for (const Vec3f& p : scene.positions) max_coord = std::max({max_coord, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  const float pad = std::ldexp(std::max(max_coord, 1e-30f), -20);

  out.pad = pad;
  Flattener flat(scene, options, out, pad);
  if (n == 0) {
    Box e;
    const uint32_t root = flat.alloc_node();
    flat.finish_node(root, make_leaf_ref(0, 1), e, make_leaf_ref(0, 1), e);
    out.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  }

  RTCDevice device = rtcNewDevice(nullptr);
  if (!device) throw std::runtime_error(fmt::format("embree: cannot create a device (error {})", int(rtcGetDeviceError(nullptr))));
  rtcSetDeviceErrorFunction(device, on_embree_error, nullptr);
  RTCBVH bvh = rtcNewBVH(device);

  const size_t capacity = options.high_quality ? n * 2 : n;
  std::vector<RTCBuildPrimitive> prims(capacity);
  for (size_t i = 0; i < n; ++i) {
    Box b;
    for (int k = 0; k < 3; ++k) b.grow(scene.positions[scene.triangles[id_of(i)].v[k]]);
    RTCBuildPrimitive& p = prims[i];
    p.lower_x = b.lo.x; p.lower_y = b.lo.y; p.lower_z = b.lo.z; p.geomID = 0;
    p.upper_x = b.hi.x; p.upper_y = b.hi.y; p.upper_z = b.hi.z; p.primID = unsigned(id_of(i));
  }

  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = options.high_quality ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
  args.buildFlags = RTC_BUILD_FLAG_NONE;
  args.maxBranchingFactor = 2;
  args.maxDepth = 48;
  args.sahBlockSize = 1;
  args.minLeafSize = 1;
  args.maxLeafSize = options.max_leaf_size;
  args.traversalCost = options.traversal_cost;
  args.intersectionCost = options.intersection_cost;
  args.bvh = bvh;
  args.primitives = prims.data();
  args.primitiveCount = n;
  args.primitiveArrayCapacity = capacity;
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = nullptr;
  args.buildProgress = nullptr;
  args.userPtr = nullptr;
  if (options.high_quality) {
    args.splitPrimitive = [](const RTCBuildPrimitive* prim, unsigned dim, float pos, RTCBounds* l, RTCBounds* r, void*) {
      // Conservative: clip the primitive's box at the plane. (Clipping the triangle's edges
      // instead, as Embree's own splitter does, was tried: SAH within 1.5 % of this on
      // bunny-armadillo, glass-dragon and cornell-box:spheres.)
      l->lower_x = prim->lower_x; l->lower_y = prim->lower_y; l->lower_z = prim->lower_z;
      l->upper_x = prim->upper_x; l->upper_y = prim->upper_y; l->upper_z = prim->upper_z;
      *r = *l;
      (&l->upper_x)[dim] = pos;
      (&r->lower_x)[dim] = pos;
    };
  }
  void* root = rtcBuildBVH(&args);
  if (!root || rtcGetDeviceError(device) != RTC_ERROR_NONE) {
    rtcReleaseBVH(bvh);
    rtcReleaseDevice(device);
    throw std::runtime_error("embree: rtcBuildBVH failed");
  }

  out.nodes.reserve(2 * n / std::max(1u, options.max_leaf_size) + 2);
  out.tris.reserve(n);
  Box root_box;
  if (static_cast<const BuildLeaf*>(root)->leaf) {
    // The whole scene is one leaf: node 0 must still be an inner node.
    const uint32_t idx = flat.alloc_node();
    Box e;
    const uint32_t r = flat.emit(root, root_box, 1);
    flat.finish_node(idx, r, root_box, make_leaf_ref(0, 1), e);
  } else {
    flat.emit(root, root_box, 0);
  }
  rtcReleaseBVH(bvh);
  rtcReleaseDevice(device);

  if (out.depth + 1 > uint32_t(kTraversalStackSize))
    throw std::runtime_error(fmt::format("bvh: depth {} exceeds the traversal stack ({})", out.depth, kTraversalStackSize));
  const double root_area = std::max(root_box.area(), 1e-30);
  out.sah_cost = (flat.inner_cost_ + flat.leaf_cost_) / root_area;
  if (options.optimize_passes > 0) {
    const BvhOptimizeResult r = optimize_treelets(out.nodes, options);
    if (r.depth + 1 > uint32_t(kTraversalStackSize)) {  // too deep for the traversal stack: Embree's tree
      BvhBuildOptions plain = options;
      plain.optimize_passes = 0;
      return build_bvh(scene, plain, leave_out);
    }
    out.depth = r.depth;
    out.treelet_passes = options.optimize_passes;
    out.sah_cost *= r.cost_after / std::max(r.cost_before, 1e-300);  // the build's SAH, scaled by the gain
  }
  out.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace pb::bvh
