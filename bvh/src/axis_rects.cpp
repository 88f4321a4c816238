// The scene's triangles paired into axis-aligned rectangles (axis_plane.h): all of them for the
// rects layout (build_axis_rects), the largest for rects-binary (largest_axis_rects).
#include <fmt/core.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <unordered_map>
#include <vector>

#include "pathbench/bvh/bvh_layout.h"

namespace pb::bvh {

namespace {
// Triangles i and j as one axis-aligned rectangle (build_axis_rects): false where they are not.
bool make_axis_rect(const Scene& scene, uint32_t i, uint32_t j, AxisRect& r, int& axis) {
  Vec3f p[2][3];
  for (int t = 0; t < 2; ++t)
    for (int c = 0; c < 3; ++c) p[t][c] = scene.positions[scene.triangles[t == 0 ? i : j].v[c]];
  for (int k = 0; k < 3; ++k) {
    const float c = p[0][0][k];
    bool flat = true;
    for (const auto& tri : p)
      for (const Vec3f& v : tri) flat = flat && v[k] == c;
    if (!flat) continue;
    const int u = k == 2 ? 0 : k + 1, v = u == 2 ? 0 : u + 1;
    float u0 = p[0][0][u], u1 = u0, v0 = p[0][0][v], v1 = v0;
    for (const auto& tri : p)
      for (const Vec3f& q : tri) {
        u0 = std::min(u0, q[u]); u1 = std::max(u1, q[u]);
        v0 = std::min(v0, q[v]); v1 = std::max(v1, q[v]);
      }
    if (!(u0 < u1 && v0 < v1)) return false;
    // Corner index of each vertex (bit 0: u1, bit 1: v1), or not a corner.
    int corner[2][3];
    for (int t = 0; t < 2; ++t)
      for (int c = 0; c < 3; ++c) {
        const Vec3f& q = p[t][c];
        if ((q[u] != u0 && q[u] != u1) || (q[v] != v0 && q[v] != v1)) return false;
        corner[t][c] = (q[u] == u1 ? 1 : 0) | (q[v] == v1 ? 2 : 0);
      }
    int mask[2] = {0, 0};
    for (int t = 0; t < 2; ++t)
      for (int c = 0; c < 3; ++c) mask[t] |= 1 << corner[t][c];
    // Each half three distinct corners, together all four, sharing a diagonal: corners
    // {0, 3} (u0v0-u1v1) or {1, 2} (u0v1-u1v0).
    if (__builtin_popcount(mask[0]) != 3 || __builtin_popcount(mask[1]) != 3 || (mask[0] | mask[1]) != 15) return false;
    const int shared = mask[0] & mask[1];
    if (shared != 0b1001 && shared != 0b0110) return false;
    const bool anti = shared == 0b0110;
    const int third_lower = __builtin_ctz(mask[0] & ~shared);  // triangle i is the lower id
    const float pu = third_lower & 1 ? u1 : u0, pv = third_lower & 2 ? v1 : v0;
    const bool lower_on_plus = detail::rect_side(u0, u1, v0, v1, anti, pu, pv) > 0.0f;
    r = AxisRect{};
    r.lo[k] = r.hi[k] = c;
    r.lo[u] = u0; r.hi[u] = u1;
    r.lo[v] = v0; r.hi[v] = v1;
    r.key = i;
    r.other = j | (anti ? kRectAntiDiagonal : 0u) | (lower_on_plus ? kRectLowerOnPlus : 0u);
    axis = k;
    return true;
  }
  return false;
}
}  // namespace

bool build_axis_rects(const Scene& scene, std::vector<AxisRect>& rects, RectGroups& groups, std::string* why) {
  const size_t n = scene.triangles.size();
  std::vector<AxisRect> by_axis[3];
  std::vector<char> paired(n, 0);
  for (uint32_t i = 0; i < n; ++i) {
    if (paired[i]) continue;
    bool found = false;
    for (uint32_t j = i + 1; j < n && !found; ++j) {
      AxisRect r;
      int axis;
      if (paired[j] || !make_axis_rect(scene, i, j, r, axis)) continue;
      paired[i] = paired[j] = 1;
      by_axis[axis].push_back(r);  // i ascending: each group in lower-id order
      found = true;
    }
    if (!found) {
      if (why) *why = fmt::format("triangle {} is not half of an axis-aligned rectangle", i);
      return false;
    }
  }
  rects.clear();
  for (int k = 0; k < 3; ++k) {
    rects.insert(rects.end(), by_axis[k].begin(), by_axis[k].end());
    groups.end[k] = uint32_t(rects.size());
  }
  return n > 0;
}

namespace {
// Triangle i's rectangle key where it could be half of an axis-aligned rectangle: its plane
// axis and value, and its box in the other two axes (a half's box is the whole rectangle).
struct RectKey {
  int axis;
  float c, u0, u1, v0, v1;
  bool operator==(const RectKey&) const = default;
};
struct RectKeyHash {
  size_t operator()(const RectKey& k) const {
    uint64_t h = uint64_t(k.axis);
    for (float f : {k.c, k.u0, k.u1, k.v0, k.v1}) {
      uint32_t b;
      std::memcpy(&b, &f, 4);
      h = (h ^ b) * 0x100000001b3ull;
    }
    return size_t(h);
  }
};
bool rect_key(const Scene& scene, uint32_t i, RectKey& key) {
  const Triangle& t = scene.triangles[i];
  const Vec3f a = scene.positions[t.v[0]], b = scene.positions[t.v[1]], c = scene.positions[t.v[2]];
  for (int k = 0; k < 3; ++k) {
    if (a[k] != b[k] || a[k] != c[k]) continue;
    const int u = k == 2 ? 0 : k + 1, v = u == 2 ? 0 : u + 1;
    key = {k, a[k], std::min({a[u], b[u], c[u]}), std::max({a[u], b[u], c[u]}), std::min({a[v], b[v], c[v]}),
           std::max({a[v], b[v], c[v]})};
    return key.u0 < key.u1 && key.v0 < key.v1;
  }
  return false;
}
}  // namespace

double largest_axis_rects(const Scene& scene, uint32_t max_rects, std::vector<AxisRect>& rects, RectGroups& groups,
                          std::vector<char>& in_rect) {
  const size_t n = scene.triangles.size();
  in_rect.assign(n, 0);
  rects.clear();
  groups = RectGroups{};
  // Unpaired candidates by key; a triangle pairs with the first earlier one make_axis_rect takes.
  std::unordered_map<RectKey, std::vector<uint32_t>, RectKeyHash> open;
  struct Found {
    AxisRect r;
    int axis;
    double area;
  };
  std::vector<Found> found;
  for (uint32_t i = 0; i < n; ++i) {
    RectKey key;
    if (!rect_key(scene, i, key)) continue;
    std::vector<uint32_t>& waiting = open[key];
    bool paired = false;
    for (size_t w = 0; w < waiting.size() && !paired; ++w) {
      Found f;
      if (!make_axis_rect(scene, waiting[w], i, f.r, f.axis)) continue;
      f.area = double(key.u1 - key.u0) * double(key.v1 - key.v0);
      found.push_back(f);
      waiting.erase(waiting.begin() + long(w));
      paired = true;
    }
    if (!paired) waiting.push_back(i);
  }
  // The largest first; of equal areas the lower ids (a stable order whatever the hash did).
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return a.area != b.area ? a.area > b.area : a.r.key < b.r.key;
  });
  if (found.size() > max_rects) found.resize(max_rects);
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return a.axis != b.axis ? a.axis < b.axis : a.r.key < b.r.key;
  });
  double area = 0;
  for (const Found& f : found) {
    rects.push_back(f.r);
    groups.end[f.axis] = uint32_t(rects.size());
    in_rect[f.r.key] = in_rect[f.r.other & kRectIdMask] = 1;
    area += f.area;
  }
  for (int k = 1; k < 3; ++k) groups.end[k] = std::max(groups.end[k], groups.end[k - 1]);
  const Vec3f e = scene.bounds_max - scene.bounds_min;
  const double surface = 2.0 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
  return surface > 0 ? area / surface : 0.0;
}

}  // namespace pb::bvh
