#pragma once
// The hit tests every traversal of the BVH library shares (binary_bvh.h, wide_bvh.h,
// leaf_list.h, brute_force.h, two_level_bvh.h): the triangle record they read (48 bytes,
// in leaf order) and the references to a leaf's run of them; the triangle test with its
// tie rule (the least (t, id) wins where a scene has instances); the slab test of a box;
// the bit helpers of child and leaf masks. Host+device code: the GPU kernels and the
// host-side tests run the same functions.
#include <cstdint>
#include <cstring>

#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"
#include "pathbench/common/moller_trumbore.h"
#include "pathbench/common/watertight.h"

namespace pb::bvh {

// Child reference (a binary node's child, a leaf list's entry, either level of the
// two-level BVH): an inner node's index, or a leaf (top bit set) holding up to
// kMaxLeafPrims consecutive triangles from `first`.
constexpr uint32_t kLeafBit = 0x80000000u;
constexpr uint32_t kMaxLeafPrims = 16;
constexpr uint32_t kLeafFirstMask = (1u << 27) - 1;  // up to 134M triangle references
PB_HD bool is_leaf(uint32_t ref) { return (ref & kLeafBit) != 0; }
PB_HD uint32_t leaf_first(uint32_t ref) { return ref & kLeafFirstMask; }
PB_HD uint32_t leaf_count(uint32_t ref) { return ((ref >> 27) & 15u) + 1; }
PB_HD uint32_t make_leaf_ref(uint32_t first, uint32_t count) { return kLeafBit | ((count - 1) << 27) | first; }

// A triangle's vertices in leaf order; v0's fourth word is the scene's triangle id.
struct alignas(16) BvhTriangle {
  float v0[3];
  uint32_t prim;
  float v1[3];
  float pad1;
  float v2[3];
  float pad2;
};
static_assert(sizeof(BvhTriangle) == 48, "BvhTriangle is 48 bytes");

constexpr uint32_t kNoHit = 0xFFFFFFFFu;

struct TraversalStats {
  uint32_t nodes = 0, tris = 0;
};

namespace detail {

PB_HD float fmadd(float a, float b, float c) {
#if defined(__CUDA_ARCH__)
  return __fmaf_rn(a, b, c);  // explicit: gpu/ builds its kernels with --fmad=false
#else
  return a * b + c;
#endif
}

PB_HD void load_triangle(const BvhTriangle* tris, uint32_t i, Vec3f& a, Vec3f& b, Vec3f& c, uint32_t& prim) {
#if defined(__CUDA_ARCH__)
  const float4* p = reinterpret_cast<const float4*>(tris + i);
  const float4 p0 = __ldg(p), p1 = __ldg(p + 1), p2 = __ldg(p + 2);
  a = {p0.x, p0.y, p0.z};
  prim = __float_as_uint(p0.w);
  b = {p1.x, p1.y, p1.z};
  c = {p2.x, p2.y, p2.z};
#else
  const BvhTriangle& t = tris[i];
  a = {t.v0[0], t.v0[1], t.v0[2]};
  b = {t.v1[0], t.v1[1], t.v1[2]};
  c = {t.v2[0], t.v2[1], t.v2[2]};
  prim = t.prim;
#endif
}

PB_HD float safe_inverse(float d) {
  constexpr float kTiny = 1e-30f;  // keeps 1/d finite, so no 0 * inf = NaN in the slabs
  return 1.0f / (std::fabs(d) > kTiny ? d : (d >= 0.0f ? kTiny : -kTiny));
}

// With `exact` (a scene with instances: its flat and two-level traversals must agree) the
// closest hit is the least (t, scene triangle id): on an exact tie in t the lower id
// wins, whatever order a traversal tests the triangles in, so that every traversal of
// one scene (binary, wide, all triangles, the instanced two-level one) names the same
// triangle. A triangle is tested against t_max widened a little past the best t so far
// (kTieSlack, far above the rounding of the test's own T < t_max * det): every triangle
// whose computed t is <= the best t is then computed in full and compared, and the
// answer depends on the triangles alone, not on the order they come in. Without it (a
// scene without instances) a triangle is tested against the best t and wins if it hits,
// as before instancing existed, so those scenes keep their images (docs/notes/gpu-log.md).
constexpr float kTieSlack = 1.0f + 0x1p-20f;
PB_HD bool closer(float tt, uint32_t prim, float t, uint32_t hit) { return tt < t || (tt == t && prim < hit); }

// Tests triangle (a, b, c), scene id `prim`, for a hit in (0, t_max) that is closer
// than (t, hit); on one narrows t to it and records prim.
template <bool kWatertight>
PB_HD bool test_vertices(const Vec3f& a, const Vec3f& b, const Vec3f& c, uint32_t prim, const WatertightRay& wr,
                         const Vec3f& o, const Vec3f& d, float t_max, bool exact, float& t, uint32_t& hit) {
  // t is t_max until the first hit.
  const float bound = exact && hit != kNoHit ? pmin(t_max, t * kTieSlack) : t;
  float tt;
  bool h;
  if constexpr (kWatertight) h = intersect_watertight(wr, a, b, c, bound, tt);
  else h = intersect_moller_trumbore(o, d, a, b, c, bound, tt);
  if (!h || (exact && !closer(tt, prim, t, hit))) return false;
  t = tt;
  hit = prim;
  return true;
}

// The same for triangle slot i of `tris`, recording the slot too. Every traversal's
// leaf test but the two-level one's (two_level_bvh.h).
template <bool kWatertight>
PB_HD bool test_triangle(const BvhTriangle* tris, uint32_t i, const WatertightRay& wr, const Vec3f& o, const Vec3f& d,
                         float t_max, bool exact, float& t, uint32_t& hit, uint32_t& hit_slot, TraversalStats* stats) {
  Vec3f a, b, c;
  uint32_t prim;
  load_triangle(tris, i, a, b, c, prim);
  if (stats) ++stats->tris;
  if (!test_vertices<kWatertight>(a, b, c, prim, wr, o, d, t_max, exact, t, hit)) return false;
  hit_slot = i;
  return true;
}

// Triangle slots [first, first + count): each tested as test_triangle does; true when an
// any-hit query (kAnyHit) is answered. A leaf of the binary BVH or of the leaves layout.
template <bool kAnyHit, bool kWatertight>
PB_HD bool test_leaf_triangles(const BvhTriangle* tris, uint32_t first, uint32_t count, const WatertightRay& wr,
                               const Vec3f& o, const Vec3f& d, float t_max, bool exact, float& t, uint32_t& hit,
                               uint32_t& hit_slot, TraversalStats* stats) {
  for (uint32_t i = first; i < first + count; ++i)
    if (test_triangle<kWatertight>(tris, i, wr, o, d, t_max, exact, t, hit, hit_slot, stats) && kAnyHit) return true;
  return false;
}

// The closest hit's answer. Woop's t ordered the candidates; the winner's t comes from
// the plane equation in double (watertight.h), accurate on grazing rays too.
template <bool kWatertight>
PB_HD uint32_t finish_closest(const BvhTriangle* tris, const Vec3f& o, const Vec3f& d, float t_max, uint32_t hit,
                              uint32_t slot, float t, float& t_hit) {
  t_hit = t;
  if (kWatertight && hit != kNoHit) {
    Vec3f a, b, c;
    uint32_t prim;
    load_triangle(tris, slot, a, b, c, prim);
    const float exact = plane_distance(o, d, a, b, c);
    if (exact > 0.0f && exact < t_max) t_hit = exact;
  }
  return hit;
}

// Bits of a mask: the traversals' child and leaf masks.
PB_HD uint32_t highest_bit(uint32_t v) {  // v != 0
#if defined(__CUDA_ARCH__)
  return 31u - uint32_t(__clz(v));
#else
  return 31u - uint32_t(__builtin_clz(v));
#endif
}
PB_HD uint32_t lowest_bit(uint32_t v) {  // v != 0
#if defined(__CUDA_ARCH__)
  return uint32_t(__ffs(v)) - 1u;
#else
  return uint32_t(__builtin_ctz(v));
#endif
}
PB_HD uint32_t popcount(uint32_t v) {
#if defined(__CUDA_ARCH__)
  return uint32_t(__popc(v));
#else
  return uint32_t(__builtin_popcount(v));
#endif
}

// The slab test's per-ray constants: t of the plane x = X is fmadd(X, inv.x, oi.x).
struct SlabRay {
  Vec3f inv, oi;
};
PB_HD SlabRay make_slab_ray(const Vec3f& o, const Vec3f& d) {
  const Vec3f inv = {safe_inverse(d.x), safe_inverse(d.y), safe_inverse(d.z)};
  return {inv, {-(o.x * inv.x), -(o.y * inv.y), -(o.z * inv.z)}};
}

// The slab test's min and max: one FMNMX each on the device, where pmin / pmax (a < b ?
// a : b) compile to a compare and a select, two instructions (16 more a binary node: a
// sixth of the paper-cornell megakernel's node loop, ncu source counters). On the host
// the ternary, which is what x86's minss / maxss compute. The two differ only where an
// operand is NaN, and slab distances of a finite ray are not: safe_inverse keeps 1/d
// finite, so fmadd of a box plane is finite or the infinite oi. Signed zeros may come
// out differently, but the traversal only compares these values, where -0 == +0: every
// decision, and so every hit, is the same as with pmin / pmax.
PB_HD float slab_min(float a, float b) {
#if defined(__CUDA_ARCH__)
  return fminf(a, b);
#else
  return pmin(a, b);
#endif
}
PB_HD float slab_max(float a, float b) {
#if defined(__CUDA_ARCH__)
  return fmaxf(a, b);
#else
  return pmax(a, b);
#endif
}

// A box's entry max(x, y, z, 0) and exit min(x, y, z) from its three slabs' near and far
// distances. On Hopper, its three-input integer max and min (DPX: VIMNMX3, one instruction
// each) on the floats' bits: 2 instructions where the float chains take 5 (measured on an
// H100: the mesh megakernels 3.8-5.1 % faster, films unchanged; docs/notes/gpu-log.md,
// 2026-11-27). Signed integers order non-negative floats as floats do (+inf included) and
// put every negative one below them, so: the entry is exact (.relu clamps at +0's bits; a
// -0 comes out +0, equal in every compare); the exit is exact when all three are > -0, and
// negative (though perhaps not the least of them) otherwise, a miss either way since the
// entry is >= 0. An exit of -0 (its bits are the least integer) beside a negative one gives
// -0 where the float chain gives the negative one; slab_far (below) makes both a miss. The
// one box the two may still decide apart is one the ray leaves at t = 0 exactly (an exit of
// -0 beside +0, which the host's ternary min may give as +0): it holds no hit t > 0, which
// the triangle test requires. PB_NO_SLAB_DPX builds the float chains on the device too.
PB_HD float slab_entry(float x, float y, float z) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900 && !defined(PB_NO_SLAB_DPX)
  return __int_as_float(__vimax3_s32_relu(__float_as_int(x), __float_as_int(y), __float_as_int(z)));
#else
  return slab_max(slab_max(x, y), slab_max(z, 0.0f));
#endif
}
PB_HD float slab_exit(float x, float y, float z) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900 && !defined(PB_NO_SLAB_DPX)
  return __int_as_float(__vimin3_s32(__float_as_int(x), __float_as_int(y), __float_as_int(z)));
#else
  return slab_min(slab_min(x, y), z);
#endif
}

// Slab distances carry a few roundings: the far end is widened (Ize 2013: by 1 + 2 gamma(3),
// that is 6u of it, u = 2^-24) and clamped to t, the best distance so far. Widened here by
// kFarUlps units in the last place on the floats' bits: an ulp is at least u of a float, so
// 6 of them are at least the product exit * (1 + 6u) rounded, which is what it was (3 to 6
// ulps): every box entered before is entered. The builders also pad every box by a few ulps
// of the scene's scale. On Hopper min(bits(exit) + 6, bits(t)) is one DPX instruction
// (VIADDMNMX) where the product and the clamp took two (docs/notes/gpu-log.md, 2026-11-27).
// t > 0, so its bits order as the float does. A non-negative exit stays so (bits at most
// 0x7F800000 + 6 where the exit is +inf, above t's as a NaN's are, so t is taken). A
// negative one, -0 included, stays negative (its bits are a negative integer and 6 more
// still is), so tf < 0 <= tn: a miss, as the float chain's negative exit is, and so is
// DPX's exit of -0 (slab_exit).
constexpr int32_t kFarUlps = 6;
PB_HD float slab_far(float exit, float t) {
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ >= 900 && !defined(PB_NO_SLAB_DPX)
  return __int_as_float(__viaddmin_s32(__float_as_int(exit), kFarUlps, __float_as_int(t)));
#else
  int32_t e, b;
  std::memcpy(&e, &exit, sizeof e);
  std::memcpy(&b, &t, sizeof b);
  e = int32_t(uint32_t(e) + uint32_t(kFarUlps));  // no signed overflow (modular from C++20)
  const int32_t m = e < b ? e : b;
  float f;
  std::memcpy(&f, &m, sizeof f);
  return f;
#endif
}

// The slab test of one box [x0, x1] x [y0, y1] x [z0, z1]: the ray enters it at tn and
// leaves at tf (clamped to [0, t], the far end widened: slab_far); it passes through the
// box before t if tn <= tf. A binary node's two children and a leaf of the leaves layout (leaf_list.h).
PB_HD void slab_interval(float x0, float x1, float y0, float y1, float z0, float z1, const SlabRay& r, float t,
                         float& tn, float& tf) {
  const float tx0 = fmadd(x0, r.inv.x, r.oi.x), tx1 = fmadd(x1, r.inv.x, r.oi.x);
  const float ty0 = fmadd(y0, r.inv.y, r.oi.y), ty1 = fmadd(y1, r.inv.y, r.oi.y);
  const float tz0 = fmadd(z0, r.inv.z, r.oi.z), tz1 = fmadd(z1, r.inv.z, r.oi.z);
  tn = slab_entry(slab_min(tx0, tx1), slab_min(ty0, ty1), slab_min(tz0, tz1));
  tf = slab_far(slab_exit(slab_max(tx0, tx1), slab_max(ty0, ty1), slab_max(tz0, tz1)), t);
}

}  // namespace detail

}  // namespace pb::bvh
