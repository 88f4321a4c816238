// Builds the two-level BVH (two_level_bvh.h) with build_bvh for every level: each
// prototype's triangles in its own coordinates, the rest of the scene's triangles as
// they are, and the instances' world boxes (each as a stand-in triangle spanning its
// box's two corners, whose box is exactly that box).
#include "pathbench/bvh/two_level_build.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace pb::bvh {

namespace {

struct Inverse {
  double m[3][4];
};

// The inverse of the affine `a`, in double; false where it has none (a copy flattened to
// zero area has lost its triangles to finalize() anyway, and stays flat).
bool invert(const Affine& a, Inverse& r) {
  const auto& m = a.m;
  const double det = a.determinant();
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return false;
  r.m[0][0] = (m[1][1] * m[2][2] - m[1][2] * m[2][1]) / det;
  r.m[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
  r.m[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
  r.m[1][0] = (m[1][2] * m[2][0] - m[1][0] * m[2][2]) / det;
  r.m[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
  r.m[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
  r.m[2][0] = (m[1][0] * m[2][1] - m[1][1] * m[2][0]) / det;
  r.m[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
  r.m[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
  for (int i = 0; i < 3; ++i) r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
  return true;
}

double max_abs(const Vec3f& p) { return std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}); }

// Grows every (non-empty) child box of `nodes` by `pad` on each side.
void pad_boxes(std::vector<BvhNode>& nodes, float pad) {
  for (BvhNode& n : nodes)
    for (int c = 0; c < 2; ++c) {
      if (!std::isfinite(n.x[2 * c])) continue;  // the empty box at +infinity stays empty
      n.x[2 * c] -= pad, n.y[2 * c] -= pad, n.z[2 * c] -= pad;
      n.x[2 * c + 1] += pad, n.y[2 * c + 1] += pad, n.z[2 * c + 1] += pad;
    }
}

// Appends `b` (a BVH over `count` items) to the bottom arrays; items: leaf slot -> the
// offset the traversal adds to first_triangle (map: the builder's item -> that offset).
template <class Map>
void append_bottom(TwoLevelHost& out, const BvhHost& b, Map map, TwoLevelInstance& in) {
  in.root = uint32_t(out.bottom_nodes.size());
  in.items = uint32_t(out.bottom_items.size());
  out.bottom_nodes.insert(out.bottom_nodes.end(), b.nodes.begin(), b.nodes.end());
  for (const BvhTriangle& t : b.tris) out.bottom_items.push_back(map(t.prim));
  out.bottom_depth = std::max(out.bottom_depth, b.depth);
}

}  // namespace

TwoLevelHost build_two_level_bvh(const Scene& s, const BvhBuildOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  TwoLevelHost out;
  out.positions = s.positions.data();
  out.triangles = s.triangles.data();

  // How far a ray's transform can stray: rays start at the camera or inside the scene and
  // end inside it, so no point of a ray that matters is farther than `reach` from the origin.
  double reach = 0;
  for (const Vec3f& p : {s.bounds_min, s.bounds_max, s.camera.position}) reach = std::max(reach, max_abs(p));
  reach = 2 * reach + length(Vec3d(s.bounds_max) - Vec3d(s.bounds_min));

  // Instances that kept all their triangles; the pad each prototype's boxes need.
  std::vector<char> covered(s.triangles.size(), 0);
  std::vector<double> proto_pad(s.prototypes.size(), -1.0);  // < 0: not instanced
  std::vector<std::pair<uint32_t, Inverse>> used;            // (scene instance, its inverse)
  for (uint32_t i = 0; i < s.instances.size(); ++i) {
    const SceneInstance& in = s.instances[i];
    const ScenePrototype& p = s.prototypes.at(in.prototype);
    const Affine m = traced_to_world(s, in);
    Inverse inv;
    if (in.triangle_count != p.triangles.size() || p.triangles.empty() || !invert(m, inv)) {
      ++out.instances_left_flat;
      continue;
    }
    // The flat triangles were rounded (to float, maybe rebased or rescaled) on their way
    // from the prototype: how far they lie from it, taken into its coordinates, plus the
    // rounding of a ray's transform (float matrix, three products and sums: far below
    // 2^-16 of the largest term).
    double norm = 0, shift = 0;
    for (int r = 0; r < 3; ++r) {
      norm = std::max(norm, std::fabs(inv.m[r][0]) + std::fabs(inv.m[r][1]) + std::fabs(inv.m[r][2]));
      shift = std::max(shift, std::fabs(inv.m[r][3]));
    }
    const double dev = norm * instance_deviation(s, in);
    const double pad = dev + std::ldexp(norm * reach + shift, -16);
    proto_pad[in.prototype] = std::max(proto_pad[in.prototype], pad);
    used.emplace_back(i, inv);
    std::fill(covered.begin() + in.first_triangle, covered.begin() + in.first_triangle + in.triangle_count, 1);
  }

  // One bottom BVH per instanced prototype, shared by its instances.
  std::vector<TwoLevelInstance> proto_bottom(s.prototypes.size());
  for (uint32_t p = 0; p < s.prototypes.size(); ++p) {
    if (proto_pad[p] < 0) continue;
    Scene local;
    local.positions = s.prototypes[p].positions;
    local.triangles = s.prototypes[p].triangles;
    BvhHost b = build_bvh(local, options);
    pad_boxes(b.nodes, float(proto_pad[p]) * (1 + 0x1p-10f));
    append_bottom(out, b, [](uint32_t k) { return k; }, proto_bottom[p]);
    ++out.prototypes;
  }
  for (const auto& [i, inv] : used) {
    const SceneInstance& in = s.instances[i];
    TwoLevelInstance r = proto_bottom[in.prototype];
    for (int row = 0; row < 3; ++row)
      for (int c = 0; c < 4; ++c) r.inv[4 * row + c] = float(inv.m[row][c]);
    r.first_triangle = in.first_triangle;
    r.pad = 0;
    out.instances.push_back(r);
  }
  out.instanced = uint32_t(out.instances.size());

  // The rest, in world coordinates: items are flat triangle ids (first_triangle 0).
  std::vector<uint32_t> rest;
  for (uint32_t t = 0; t < s.triangles.size(); ++t)
    if (!covered[t]) rest.push_back(t);
  if (!rest.empty()) {
    Scene local;
    local.positions = s.positions;
    for (uint32_t t : rest) local.triangles.push_back(s.triangles[t]);
    TwoLevelInstance r{};
    r.inv[0] = r.inv[5] = r.inv[10] = 1.0f;  // the identity: the walk sees the world ray, exactly
    append_bottom(out, build_bvh(local, options), [&](uint32_t k) { return rest[k]; }, r);
    out.instances.push_back(r);
  }
  out.flat_triangles = uint32_t(rest.size());

  // The top level over the instances' world boxes (of their flat triangles).
  Scene boxes;
  auto add_box = [&](auto&& each_triangle) {
    Vec3f lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    each_triangle([&](uint32_t t) {
      for (uint32_t v : s.triangles[t].v) lo = vmin(lo, s.positions[v]), hi = vmax(hi, s.positions[v]);
    });
    const uint32_t base = uint32_t(boxes.positions.size());
    boxes.positions.push_back(lo);
    boxes.positions.push_back(hi);
    boxes.triangles.push_back({{base, base + 1, base}});  // its box: exactly [lo, hi]
  };
  for (const auto& [i, inv] : used) {
    const SceneInstance& in = s.instances[i];
    add_box([&](auto&& f) { for (uint32_t k = 0; k < in.triangle_count; ++k) f(in.first_triangle + k); });
  }
  if (!rest.empty()) add_box([&](auto&& f) { for (uint32_t t : rest) f(t); });
  const BvhHost top = build_bvh(boxes, options);
  out.top_nodes = top.nodes;
  for (const BvhTriangle& t : top.tris) out.top_items.push_back(t.prim);
  out.top_depth = top.depth;
  out.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace pb::bvh
