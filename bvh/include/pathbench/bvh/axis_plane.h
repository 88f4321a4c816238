#pragma once
// Scenes of axis-aligned rectangles (GpuBvhLayout::Rects, traced through the leaves layout's
// kernels): every triangle is half of a rectangle that lies in a plane x, y or z = c and
// whose sides run along the other two axes (paper-cornell: its 6 walls and the light, 14
// triangles). Such a rectangle needs no triangle test: it is a box of zero thickness, and
// a ray hits it where the slab test of that flat box says so. One record a rectangle
// (AxisRect: two 16-byte loads), its exact extents (no padding), lo[k] == hi[k] == c on its
// plane's axis k; the records come grouped by k (RectGroups), so that each group's loop
// knows its axis at compile time.
//
// The test. t of the plane {p : p_a = A} along the ray is plane_t = (A - o_a) * inv_a, inv
// the slab ray's reciprocals. A rectangle in plane k = c with sides [u0, u1] x [v0, v1]
// is hit at t_k = plane_t(c) when t_k lies in both slabs [plane_t(u0), plane_t(u1)] and
// [plane_t(v0), plane_t(v1)] (ends sorted, both inclusive). No shear, no division beyond
// the three reciprocals, no double but one division for the winner's t.
//
// Watertight by construction: every t that decides a hit is plane_t of one (axis, value),
// the same float whichever rectangle asks for it. Where two rectangles meet at an edge
// (the line a = A, k = c), one asks whether t_k <= plane_t(A) and the other whether
// plane_t(A) <= t_k (or the reverse): the same two floats compared, both inclusive, so a
// ray towards the edge from either side hits at least one of them; at a corner of three
// rectangles the three comparisons are of three floats, a total order, so one of them is
// least and its rectangle is hit (a test that compared in-plane points p_u = o_u + t d_u
// would round each rectangle's point apart and could let a ray pass a corner).
//
// The answer. The closest hit is the least (t_k, key) (key: the rectangle's lower
// triangle id; the least-(t, id) rule of hit_tests.h, whatever order the groups come in);
// its t is then recomputed from the same plane as (c - o_k) / d_k in double, rounded once
// (plane_distance's answer for such a triangle but in rare double roundings), and its
// triangle is the half of the rectangle on the hit point's side of the shared diagonal
// (one edge function of the hit point; a point exactly on it takes the lower id).
// ray_t_min's least t, bit for bit (min |inv| is 1 / max |d|). Host+device.
#include <cstdint>
#include <cstring>

#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"

namespace pb::bvh {

// Rectangles [0, end[0]) lie in planes x = c, [end[0], end[1]) in y = c, [end[1], end[2]) in z = c.
struct RectGroups {
  uint32_t end[3] = {0, 0, 0};
};

// A rectangle: its extents, the lower triangle id of its two halves (`key`) and the other
// id with the flags below (`other`).
struct alignas(16) AxisRect {
  float lo[3];
  uint32_t key;
  float hi[3];
  uint32_t other;
};
static_assert(sizeof(AxisRect) == 32, "AxisRect is two 16-byte loads");

constexpr uint32_t kRectAntiDiagonal = 1u << 31;  // the diagonal runs (u0, v1)-(u1, v0), else (u0, v0)-(u1, v1)
constexpr uint32_t kRectLowerOnPlus = 1u << 30;   // the lower id's half is where rect_side() > 0
constexpr uint32_t kRectIdMask = kRectLowerOnPlus - 1;

namespace detail {

PB_HD float plane_t(float a, float o, float inv) { return (a - o) * inv; }

// A 32-byte box record (AxisRect here, leaf_list.h's LeafBox): lo[3], a word, hi[3], a word;
// on the device two 16-byte loads.
template <class Box>
PB_HD void load_box_record(const Box* boxes, uint32_t i, float (&lo)[3], float (&hi)[3], uint32_t& w3, uint32_t& w7) {
  static_assert(sizeof(Box) == 32 && alignof(Box) == 16, "two 16-byte loads");
#if defined(__CUDA_ARCH__)
  const float4* p = reinterpret_cast<const float4*>(boxes + i);
  const float4 a = __ldg(p), b = __ldg(p + 1);
  lo[0] = a.x; lo[1] = a.y; lo[2] = a.z;
  w3 = __float_as_uint(a.w);
  hi[0] = b.x; hi[1] = b.y; hi[2] = b.z;
  w7 = __float_as_uint(b.w);
#else
  const unsigned char* p = reinterpret_cast<const unsigned char*>(boxes + i);
  std::memcpy(lo, p, 12);
  std::memcpy(&w3, p + 12, 4);
  std::memcpy(hi, p + 16, 12);
  std::memcpy(&w7, p + 28, 4);
#endif
}

PB_HD void load_rect(const AxisRect* rects, uint32_t i, float (&lo)[3], float (&hi)[3], uint32_t& key,
                     uint32_t& other) {
  load_box_record(rects, i, lo, hi, key, other);
}

// Which side of the rectangle's diagonal the in-plane point (pu, pv) lies on (u = k + 1,
// v = k + 2 mod 3): > 0, < 0 or 0 on it. The builder asks it of each half's third corner.
PB_HD float rect_side(float u0, float u1, float v0, float v1, bool anti, float pu, float pv) {
  const float av = anti ? v1 : v0, ev = anti ? v0 - v1 : v1 - v0;
  return (pu - u0) * ev - (pv - av) * (u1 - u0);
}

// Rectangles [begin, end) of plane axis k: the least (t, key) hit with t_min < t (<= t:
// ties by key) into (t, best, best_key); any hit: true at the first.
template <int k, bool kAnyHit>
PB_HD bool test_rect_group(const AxisRect* rects, uint32_t begin, uint32_t end, const Vec3f& o, const Vec3f& inv,
                           float t_min, float& t, uint32_t& best, uint32_t& best_key, TraversalStats* stats) {
  constexpr int u = k == 2 ? 0 : k + 1, v = u == 2 ? 0 : u + 1;
  for (uint32_t i = begin; i < end; ++i) {
    float lo[3], hi[3];
    uint32_t key, other;
    load_rect(rects, i, lo, hi, key, other);
    if (stats) ++stats->nodes;
    const float tk = plane_t(lo[k], o[k], inv[k]);
    if (!(tk > t_min && tk <= t)) continue;
    const float u0 = plane_t(lo[u], o[u], inv[u]), u1 = plane_t(hi[u], o[u], inv[u]);
    const float v0 = plane_t(lo[v], o[v], inv[v]), v1 = plane_t(hi[v], o[v], inv[v]);
    if (!(slab_max(slab_min(u0, u1), slab_min(v0, v1)) <= tk && tk <= slab_min(slab_max(u0, u1), slab_max(v0, v1))))
      continue;
    if (!(tk < t || key < best_key)) continue;  // tk == t: the lower key wins (best_key 0: t is t_max, exclusive)
    t = tk;
    best = i;
    best_key = key;
    if (kAnyHit) return true;
  }
  return false;
}

}  // namespace detail

// Closest hit (kAnyHit = false) or any hit among the rectangles, in (ray_t_min, t_max):
// the scene triangle id or kNoHit, t in t_hit.
template <bool kAnyHit>
PB_HD uint32_t traverse_rects(const AxisRect* rects, const RectGroups& g, const Vec3f& o, const Vec3f& d, float t_max,
                              float& t_hit, TraversalStats* stats = nullptr) {
  const Vec3f inv = {detail::safe_inverse(d.x), detail::safe_inverse(d.y), detail::safe_inverse(d.z)};
  const Vec3f ai = vabs(inv);
  const float t_min = 0x1p-21f * max_component(vabs(o)) * pmin(ai.x, pmin(ai.y, ai.z));  // ray_t_min(o, d)
  float t = t_max;
  uint32_t best = kNoHit, key = 0;
  if (detail::test_rect_group<0, kAnyHit>(rects, 0, g.end[0], o, inv, t_min, t, best, key, stats) ||
      detail::test_rect_group<1, kAnyHit>(rects, g.end[0], g.end[1], o, inv, t_min, t, best, key, stats) ||
      detail::test_rect_group<2, kAnyHit>(rects, g.end[1], g.end[2], o, inv, t_min, t, best, key, stats)) {
    t_hit = t;
    return key;  // any hit: some triangle of the rectangle hit
  }
  t_hit = t;
  if (best == kNoHit) return kNoHit;
  float lo[3], hi[3];
  uint32_t other;
  detail::load_rect(rects, best, lo, hi, key, other);
  const int kk = best < g.end[0] ? 0 : (best < g.end[1] ? 1 : 2);
  const int ku = kk == 2 ? 0 : kk + 1, kv = ku == 2 ? 0 : ku + 1;
  const float exact = float((double(lo[kk]) - double(o[kk])) / double(d[kk]));
  if (exact > 0.0f && exact < t_max) t_hit = exact;
  const float pu = pb::fmadd(t_hit, d[ku], o[ku]), pv = pb::fmadd(t_hit, d[kv], o[kv]);  // fused on both devices alike
  const float s = detail::rect_side(lo[ku], hi[ku], lo[kv], hi[kv], (other & kRectAntiDiagonal) != 0, pu, pv);
  const bool lower_on_plus = (other & kRectLowerOnPlus) != 0;
  if (s == 0.0f || (s > 0.0f) == lower_on_plus) return key;
  return other & kRectIdMask;
}

}  // namespace pb::bvh
