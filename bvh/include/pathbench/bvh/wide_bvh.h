#pragma once
// The GPU's wide BVH: up to 8 children a node, their boxes quantised to 8 bits per axis
// relative to the node's own box (Ylitie, Karras & Laine, "Efficient Incoherent Ray
// Traversal on GPUs Through Compressed Wide BVHs", HPG 2017). An 80-byte node replaces
// up to 7 binary 64-byte nodes, so a ray reads about a third of the node bytes and
// keeps far fewer stack entries. Built on the host by collapsing the binary BVH
// (bvh/src/wide_bvh_build.cpp); the traversal below is host+device code, so the
// host-side tests run exactly what the kernels run.
//
// Traversal follows the paper: a stack of "node groups" (the base index of a node's inner
// children + a mask of the ones the ray hit, ordered by the ray's octant so that popping
// the highest bit takes the child nearest the ray's origin first), the hit leaves'
// triangles tested as soon as the node is (one bit each in the low 24 bits). The stack can
// be a short one in registers (WideShortStack: the kWideShortStack most recent groups, as
// Vaidyanathan, Woop & Benthin, HPG 2019, keep theirs), over a backing array in local
// memory for the older ones: nothing is dropped and no restart is needed, so the visit
// order, and every hit, is that of a plain stack. Measured slower on the GPU (below): the
// default is the plain stack in local memory.
#include <cstdint>
#include <cstring>

#include "pathbench/bvh/hit_tests.h"
#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"

// The per-node loops must unroll on the device: their small arrays then live in
// registers, not in local memory.
#if defined(__CUDA_ARCH__)
#define PB_WIDE_UNROLL _Pragma("unroll")
#else
#define PB_WIDE_UNROLL
#endif

namespace pb::bvh {

constexpr uint32_t kWideMaxChildren = 8;
constexpr uint32_t kWideMaxLeafTris = 3;  // unary count in the top 3 bits of meta
constexpr int kWideStackSize = 64;        // one entry per level at most; the builder checks the depth
// Groups held in registers (WideShortStack); 0: a plain stack in local memory.
// -DPB_WIDE_SHORT_STACK=N builds another size. Measured on an H100 (paper-cornell-ico:8,
// 256x256x800 nee, megakernel; docs/notes/gpu-log.md, "Wide BVH: own occupancy, short
// stack"): 4 groups in registers took 104.2 ms at 5 blocks an SM, the plain stack 92.2: at
// the 48 to 64 registers a wide megakernel may hold, 8 more live registers push path state
// into spills (ptxas: 5 blocks, 932 / 848 bytes spilled with it). So 0 by default.
#ifndef PB_WIDE_SHORT_STACK
#define PB_WIDE_SHORT_STACK 0
#endif
constexpr int kWideShortStack = PB_WIDE_SHORT_STACK;

// One node. Child i's box is p + 2^(e - 127) * q in each axis, rounded outward when
// built, so it holds the child's real box. meta[i]: 0 for an empty slot; an inner child
// 0b001'(24 + i); a leaf (count 1..3 triangles from tri_base + offset) the count in unary
// in the top 3 bits over the 5-bit offset. Inner children are stored contiguously from
// child_base in slot order (the k-th set bit of imask is child_base + k).
struct alignas(16) WideNode {
  float p[3];
  uint8_t e[3];
  uint8_t imask;
  uint32_t child_base;
  uint32_t tri_base;
  uint8_t meta[8];
  uint8_t qlo[3][8];  // [axis][slot]
  uint8_t qhi[3][8];
};
static_assert(sizeof(WideNode) == 80, "WideNode is five 16-byte loads");

struct WideBvhView {
  const WideNode* nodes;  // node 0 is the root
  const BvhTriangle* tris;
  uint32_t num_nodes;
  uint32_t num_tris;
  uint32_t exact_ties = 0;  // as BinaryBvhView's
};

namespace detail {

PB_HD float exp2_of_byte(uint32_t e) {  // 2^(e - 127) for e in 1..254: a normal float
  const uint32_t bits = e << 23;
#if defined(__CUDA_ARCH__)
  return __uint_as_float(bits);
#else
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
#endif
}

// The node as 20 words: p.xyz, e+imask, child_base, tri_base, meta (2), qlo (6), qhi (6).
PB_HD void load_wide_node(const WideNode* nodes, uint32_t i, uint32_t (&w)[20]) {
#if defined(__CUDA_ARCH__)
  const uint4* p = reinterpret_cast<const uint4*>(nodes + i);
  PB_WIDE_UNROLL
  for (int k = 0; k < 5; ++k) {
    const uint4 v = __ldg(p + k);
    w[4 * k] = v.x; w[4 * k + 1] = v.y; w[4 * k + 2] = v.z; w[4 * k + 3] = v.w;
  }
#else
  std::memcpy(w, nodes + i, sizeof(WideNode));
#endif
}

PB_HD float word_as_float(uint32_t w) {
#if defined(__CUDA_ARCH__)
  return __uint_as_float(w);
#else
  float f;
  std::memcpy(&f, &w, sizeof f);
  return f;
#endif
}

// Byte `k` (0..3) of the 32-bit word `w` as a float, exactly: the bits of 2^23 + q,
// minus 2^23. On the GPU one PRMT and one FADD: an int-to-float conversion (I2F) issues
// at a quarter or less of the FADD rate, and a node needs 48 of them.
PB_HD float byte_as_float(uint32_t w, int k) {
#if defined(__CUDA_ARCH__)
  const uint32_t bits = __byte_perm(w, 0x4B000000u, 0x7440u | uint32_t(k));
#else
  const uint32_t bits = 0x4B000000u | ((w >> (8 * k)) & 0xFFu);
#endif
  return word_as_float(bits) - 8388608.0f;
}

// A stack entry: a node's inner children from `base` and which of them are left to visit
// (bits 24..31, octant order), with the node's imask in bits 0..7.
struct WideGroup {
  uint32_t base, hits;
};

// The traversal stack: the N most recent groups in registers (top[0] the newest; every
// index a constant once unrolled, so the array is registers, and a push or pop is 2N moves),
// the older ones in the caller's `spill` array (local memory), touched only when more than
// N are held. The spill array is not a member: an aggregate holding a dynamically indexed
// array is kept whole in local memory by the compiler (the PTX of k_trace showed `top` in
// the local depot), so the two live apart.
template <int N>
struct WideShortStack {
  WideGroup top[N] = {};
  int size = 0;

  PB_HD bool empty() const { return size == 0; }
  PB_HD void push(const WideGroup& g, WideGroup* spill) {
    if (size >= N) spill[size - N] = top[N - 1];
    PB_WIDE_UNROLL
    for (int k = N - 1; k > 0; --k) top[k] = top[k - 1];
    top[0] = g;
    ++size;
  }
  PB_HD WideGroup pop(const WideGroup* spill) {  // !empty()
    const WideGroup g = top[0];
    PB_WIDE_UNROLL
    for (int k = 0; k < N - 1; ++k) top[k] = top[k + 1];
    --size;
    if (size >= N) top[N - 1] = spill[size - N];
    return g;
  }
};
template <>
struct WideShortStack<0> {  // the plain stack: every group in `spill`
  int size = 0;
  PB_HD bool empty() const { return size == 0; }
  PB_HD void push(const WideGroup& g, WideGroup* spill) { spill[size++] = g; }
  PB_HD WideGroup pop(const WideGroup* spill) { return spill[--size]; }
};
constexpr int kWideSpillSize = kWideStackSize - kWideShortStack;

}  // namespace detail

// Closest hit (kAnyHit = false) or any hit, as traverse() in binary_bvh.h: same triangle test,
// same answer (the triangle with the smallest t; of two at exactly the same t, the lower
// id: detail::closer).
template <bool kAnyHit, bool kWatertight = true>
PB_HD uint32_t traverse_wide(const WideBvhView& bvh, const Vec3f& o, const Vec3f& d, float t_max, float& t_hit,
                             TraversalStats* stats = nullptr) {
  const WatertightRay wr = make_watertight_ray(o, d);
  const auto [inv, oi] = detail::make_slab_ray(o, d);
  // Octant of the direction, inverted: child slots are numbered by the corner of the
  // node they lie toward (bit set = + side), so slot s ^ oct_inv == 7 is entered first.
  const uint32_t oct = (d.x < 0.0f ? 1u : 0u) | (d.y < 0.0f ? 2u : 0u) | (d.z < 0.0f ? 4u : 0u);
  const uint32_t oct_inv = 7u - oct;
  // Per axis: which of the two quantised planes is near (the lo plane for d >= 0).
  const bool neg[3] = {inv.x < 0.0f, inv.y < 0.0f, inv.z < 0.0f};
  const float inv_a[3] = {inv.x, inv.y, inv.z}, oi_a[3] = {oi.x, oi.y, oi.z};

  detail::WideShortStack<kWideShortStack> stack;
  detail::WideGroup spill[detail::kWideSpillSize];
  // The root as the only child of a virtual node: popping bit 31 gives slot 7 ^ oct_inv,
  // and an empty imask makes its index base + 0.
  detail::WideGroup ng{0u, 0x80000000u};
  uint32_t hit = kNoHit, hit_slot = 0;
  float t = t_max;
  for (;;) {
    uint32_t tbase = 0, thits = 0;
    if (ng.hits & 0xFF000000u) {
      const uint32_t bit = detail::highest_bit(ng.hits & 0xFF000000u);
      ng.hits &= ~(1u << bit);
      const uint32_t slot = (bit - 24u) ^ oct_inv;
      const uint32_t index = ng.base + detail::popcount(ng.hits & 0xFFu & ((1u << slot) - 1u));
      if (ng.hits & 0xFF000000u) stack.push(ng, spill);
      uint32_t w[20];
      detail::load_wide_node(bvh.nodes, index, w);
      if (stats) ++stats->nodes;
      const uint32_t e_imask = w[3];
      const uint32_t imask = e_imask >> 24;
      float a[3], b[3];
      PB_WIDE_UNROLL
      for (int k = 0; k < 3; ++k) {
        a[k] = detail::exp2_of_byte((e_imask >> (8 * k)) & 0xFFu) * inv_a[k];
        b[k] = detail::fmadd(detail::word_as_float(w[k]), inv_a[k], oi_a[k]);
      }
      uint32_t hitmask = 0;
      PB_WIDE_UNROLL
      for (int half = 0; half < 2; ++half) {  // slots 4 * half .. 4 * half + 3
        const uint32_t meta4 = w[6 + half];
        uint32_t qn[3], qf[3];
        PB_WIDE_UNROLL
        for (int k = 0; k < 3; ++k) {
          const uint32_t lo = w[8 + 2 * k + half], hi = w[14 + 2 * k + half];
          qn[k] = neg[k] ? hi : lo;
          qf[k] = neg[k] ? lo : hi;
        }
        PB_WIDE_UNROLL
        for (int j = 0; j < 4; ++j) {
          const uint32_t meta = (meta4 >> (8 * j)) & 0xFFu;
          const float tx0 = detail::fmadd(detail::byte_as_float(qn[0], j), a[0], b[0]);
          const float ty0 = detail::fmadd(detail::byte_as_float(qn[1], j), a[1], b[1]);
          const float tz0 = detail::fmadd(detail::byte_as_float(qn[2], j), a[2], b[2]);
          const float tx1 = detail::fmadd(detail::byte_as_float(qf[0], j), a[0], b[0]);
          const float ty1 = detail::fmadd(detail::byte_as_float(qf[1], j), a[1], b[1]);
          const float tz1 = detail::fmadd(detail::byte_as_float(qf[2], j), a[2], b[2]);
          const float tn = detail::slab_entry(tx0, ty0, tz0);
          const float tf = detail::slab_far(detail::slab_exit(tx1, ty1, tz1), t);
          if (meta != 0 && tn <= tf) {
            const uint32_t slot = 4u * half + j;
            const bool inner = (imask >> slot) & 1u;
            const uint32_t index = inner ? ((meta & 0x1Fu) ^ oct_inv) : (meta & 0x1Fu);
            hitmask |= (meta >> 5) << index;
          }
        }
      }
      ng = {w[4], (hitmask & 0xFF000000u) | imask};
      tbase = w[5];
      thits = hitmask & 0x00FFFFFFu;
    }
    while (thits) {
      const uint32_t k = detail::lowest_bit(thits);
      thits &= thits - 1u;
      const uint32_t i = tbase + k;
      if (detail::test_triangle<kWatertight>(bvh.tris, i, wr, o, d, t_max, bvh.exact_ties != 0, t, hit, hit_slot, stats) &&
          kAnyHit) {
        t_hit = t;
        return hit;
      }
    }
    if (!(ng.hits & 0xFF000000u)) {
      if (stack.empty()) break;
      ng = stack.pop(spill);
    }
  }
  return detail::finish_closest<kWatertight>(bvh.tris, o, d, t_max, hit, hit_slot, t, t_hit);
}

}  // namespace pb::bvh
