// (No include guard: included once per instruction set, see shade_x8.h.)
// The lanes of the CPU's batched shading (shade_x8.h): 8 floats (AVX2) or 16 (AVX-512)
// as PB_SIMD_LANES says, written with GCC's vector extensions and a few intrinsics;
// compiled only under the matching `#pragma GCC target` (shade_avx2.cpp,
// shade_avx512.cpp), used only on CPUs that have it. Every operation here is the
// lane-wise twin of the scalar one the path step uses (IEEE +, -, *, /, sqrt,
// compare-and-select, and FMA -- madd -- exactly where the scalar code calls pb::fmadd;
// never a contraction of the compiler's own: -ffp-contract=off), so a lane computes bit
// for bit what the scalar path step computes for that path, whatever the width.
#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "pathbench/common/math.h"
#include "pathbench/common/ray_offset.h"

#if PB_SIMD_LANES != 8 && PB_SIMD_LANES != 16
#error "PB_SIMD_LANES must be 8 (AVX2) or 16 (AVX-512)"
#endif

namespace pb::cpu::PB_SIMD_NS {

constexpr int kLanes = PB_SIMD_LANES;
typedef float FV __attribute__((vector_size(4 * kLanes)));
typedef int32_t IV __attribute__((vector_size(4 * kLanes)));  // masks: -1 (true) or 0
typedef uint32_t UV __attribute__((vector_size(4 * kLanes)));

// Three lanes-vectors: math.h's Vec3 operations, lane-wise and in the same order. (Not
// Vec3<FV>: math.h's templates would be instantiated outside the target region, with the
// baseline calling convention for 32- and 64-byte vectors.)
struct V3 {
  FV x, y, z;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 operator*(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline V3 operator*(V3 a, FV s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator/(V3 a, FV s) { return {a.x / s, a.y / s, a.z / s}; }
inline FV dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

inline FV splat(float x) { return FV{} + x; }
inline FV splat(FV x) { return x; }
// x in every lane as one broadcast instruction: splat's + 0.0f must be kept (it turns -0.0
// into +0.0), so the compiler cannot make it one. For values whose sign of zero does not
// matter (the tiny-scene test's tables, tiny_x8.h).
#if PB_SIMD_LANES == 16
inline FV bcast(const float& x) { return FV(_mm512_set1_ps(x)); }
#else
inline FV bcast(const float& x) { return FV(_mm256_set1_ps(x)); }
#endif
// kLanes floats from p (any alignment): one load.
#if PB_SIMD_LANES == 16
inline FV load_lanes(const float* p) { return FV(_mm512_loadu_ps(p)); }
#else
inline FV load_lanes(const float* p) { return FV(_mm256_loadu_ps(p)); }
#endif

// pb::fmadd (math.h) lane-wise: a * b + c, one rounding (a float operand is broadcast).
// With math.h's fused vector operations, each the twin of the scalar one.
#if PB_SIMD_LANES == 16
inline FV madd_v(FV a, FV b, FV c) { return FV(_mm512_fmadd_ps(__m512(a), __m512(b), __m512(c))); }
#else
inline FV madd_v(FV a, FV b, FV c) { return FV(_mm256_fmadd_ps(__m256(a), __m256(b), __m256(c))); }
#endif
template <class A, class B, class C> inline FV madd(A a, B b, C c) { return madd_v(splat(a), splat(b), splat(c)); }
inline V3 madd(V3 a, FV s, V3 c) { return {madd(a.x, s, c.x), madd(a.y, s, c.y), madd(a.z, s, c.z)}; }
inline FV fdot(V3 a, V3 b) { return madd(a.x, b.x, madd(a.y, b.y, a.z * b.z)); }
inline V3 fcross(V3 a, V3 b) {
  return {madd(a.y, b.z, -(a.z * b.y)), madd(a.z, b.x, -(a.x * b.z)), madd(a.x, b.y, -(a.y * b.x))};
}
inline IV splat_i(int32_t x) { return IV{} + x; }
inline IV bits(FV v) { return (IV)v; }  // a cast between vector types of one size keeps the bits
inline FV from_bits(IV v) { return (FV)v; }
// m ? a : b per lane (m from a comparison).
inline FV select(IV m, FV a, FV b) { return m ? a : b; }
inline IV select_i(IV m, IV a, IV b) { return m ? a : b; }
inline V3 select(IV m, V3 a, V3 b) { return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z}; }
// pmin / pmax of math.h, lane-wise: the same comparison picks the same operand (NaN too).
inline FV vmin(FV a, FV b) { return a < b ? a : b; }
inline FV vmax(FV a, FV b) { return a > b ? a : b; }
// Bit i: lane i of mask m is set (movemask: "any lane" is lane_mask(m) != 0, one
// instruction, where a loop over the lanes tests them one by one).
#if PB_SIMD_LANES == 16
inline uint32_t lane_mask(IV m) { return uint32_t(_mm512_movepi32_mask(__m512i(m))); }
#else
inline uint32_t lane_mask(IV m) { return uint32_t(_mm256_movemask_ps(__m256(m))); }
#endif

#if PB_SIMD_LANES == 8
// kPackOrder.v[m]: the set bits of m (8 bits) in increasing order, one nibble each from
// the lowest (Packer's permutation).
struct PackOrder {
  uint32_t v[256];
  constexpr PackOrder() : v() {
    for (uint32_t m = 0; m < 256; ++m) {
      uint32_t packed = 0, k = 0;
      for (uint32_t i = 0; i < 8; ++i)
        if ((m >> i) & 1) packed |= i << (4 * k++);
      v[m] = packed;
    }
  }
};
inline constexpr PackOrder kPackOrder{};
#endif

// The lanes picked by a bit mask, packed to the front in lane order and stored as
// consecutive entries (a compress store): how the shading kernel appends the paths of
// one kind (going on, shadowed, ...) to its caller's arrays. Only popcount(mask) entries
// are written, never more: the wavefront appends in place to arrays it is still reading.
struct Packer {
#if PB_SIMD_LANES == 16
  explicit Packer(uint32_t mask) : count(__builtin_popcount(mask)), m(__mmask16(mask)), first(__mmask16((1u << count) - 1)) {}
  void store(float* p, FV v) const { _mm512_mask_storeu_ps(p, first, _mm512_maskz_compress_ps(m, __m512(v))); }
  void store(uint32_t* p, UV v) const { _mm512_mask_storeu_epi32(p, first, _mm512_maskz_compress_epi32(m, __m512i(v))); }
  int count;
  __mmask16 m, first;
#else
  // AVX2 has no compress: a permutation from a table (lane numbers, a nibble each), then
  // a masked store of the first popcount(mask) lanes.
  explicit Packer(uint32_t mask)
      : count(__builtin_popcount(mask)),
        idx(_mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(int32_t(kPackOrder.v[mask & 0xFF])),
                                               _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28)),
                             _mm256_set1_epi32(7))),
        first(_mm256_cmpgt_epi32(_mm256_set1_epi32(count), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7))) {}
  void store(float* p, FV v) const { _mm256_maskstore_ps(p, first, _mm256_permutevar8x32_ps(__m256(v), idx)); }
  void store(uint32_t* p, UV v) const {
    _mm256_maskstore_epi32(reinterpret_cast<int*>(p), first, _mm256_permutevar8x32_epi32(__m256i(v), idx));
  }
  int count;
  __m256i idx, first;
#endif
};

// The first n lanes of v to p[0..n) (n <= kLanes; nothing past them is written).
inline void store_first(float* p, FV v, int n) {
#if PB_SIMD_LANES == 16
  _mm512_mask_storeu_ps(p, __mmask16((1u << n) - 1), __m512(v));
#else
  _mm256_maskstore_ps(p, _mm256_cmpgt_epi32(_mm256_set1_epi32(n), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)), __m256(v));
#endif
}

#if PB_SIMD_LANES == 16
inline FV sqrt(FV a) { return FV(_mm512_sqrt_ps(__m512(a))); }
#else
inline FV sqrt(FV a) { return FV(_mm256_sqrt_ps(__m256(a))); }
#endif
inline FV abs(FV a) { return from_bits(bits(a) & 0x7fffffff); }
inline FV copysign(FV mag, FV sign) { return from_bits((bits(mag) & 0x7fffffff) | (bits(sign) & int32_t(0x80000000u))); }

// As math.h: a * (1 / length(a)), unfused and fused.
inline V3 normalize(V3 a) { return a * (1.0f / sqrt(dot(a, a))); }
inline V3 fnormalize(V3 a) { return a * (1.0f / sqrt(fdot(a, a))); }

// Frame<T>::from_normal (math.h), lane-wise, in the same order of operations.
struct FrameV {
  V3 s, t, n;
  static FrameV from_normal(V3 n) {
    const FV sign = copysign(splat(1.0f), n.z);
    const FV a = -1.0f / (sign + n.z);
    const FV b = n.x * n.y * a;
    return {{madd(n.x * n.x, sign * a, 1.0f), sign * b, -sign * n.x}, {b, madd(n.y * n.y, a, sign), -n.y}, n};
  }
  V3 to_world(V3 v) const { return madd(s, v.x, madd(t, v.y, n * v.z)); }
};

// offset_ray_origin (ray_offset.h) lane-wise: the float-grid move along n.
inline FV offset_coord(FV pc, FV nc, const RayOffset& off) {
  const FV near_moved = madd(off.fixed_distance, nc, pc);
  const IV of = __builtin_convertvector(256.0f * nc, IV);  // truncation, as int32_t(float)
  const IV far_bits = bits(pc) + ((pc < 0.0f) ? -of : of);
  return select(abs(pc) < off.near_origin, near_moved, from_bits(far_bits));
}
inline V3 offset_ray_origin(V3 p, V3 n, const RayOffset& off) {
  return {offset_coord(p.x, n.x, off), offset_coord(p.y, n.y, off), offset_coord(p.z, n.z, off)};
}



// 8-float records ("rows") to lanes and back: lane i of out[j] is rows[i][j].
// Eight rows at a time: each 4x4 block is transposed inside a 128-bit half; the halves
// come straight from memory (rows i and i + 4 share a register), so eight rows are 16
// loads and 16 shuffles. Sixteen lanes are two such groups joined into one register.
[[gnu::always_inline]] inline void transpose4_halves(__m256 r0, __m256 r1, __m256 r2, __m256 r3, __m256* out) {
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  out[0] = _mm256_shuffle_ps(t0, t2, 0x44);
  out[1] = _mm256_shuffle_ps(t0, t2, 0xEE);
  out[2] = _mm256_shuffle_ps(t1, t3, 0x44);
  out[3] = _mm256_shuffle_ps(t1, t3, 0xEE);
}
[[gnu::always_inline]] inline __m256 two_halves(const float* lo, const float* hi) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1);
}
// Rows p[0..8) (already offset) to eight 8-lane registers.
[[gnu::always_inline]] inline void load_rows8(const float* const p[8], __m256 out[8]) {
  transpose4_halves(two_halves(p[0], p[4]), two_halves(p[1], p[5]), two_halves(p[2], p[6]), two_halves(p[3], p[7]), out);
  transpose4_halves(two_halves(p[0] + 4, p[4] + 4), two_halves(p[1] + 4, p[5] + 4), two_halves(p[2] + 4, p[6] + 4),
                    two_halves(p[3] + 4, p[7] + 4), out + 4);
}
// Eight 8-lane registers to rows q[0..lanes) (lanes <= 8).
[[gnu::always_inline]] inline void store_rows8(const __m256 in[8], float* const q[8], int lanes) {
  __m256 t[8];
  transpose4_halves(in[0], in[1], in[2], in[3], t);
  transpose4_halves(in[4], in[5], in[6], in[7], t + 4);
  // t[i] (i < 4): row i, columns 0-3 | row i + 4, columns 0-3; t[i + 4]: the same for columns 4-7.
  for (int i = 0; i < 4; ++i) {
    if (i < lanes) {
      _mm_storeu_ps(q[i], _mm256_castps256_ps128(t[i]));
      _mm_storeu_ps(q[i] + 4, _mm256_castps256_ps128(t[i + 4]));
    }
    if (i + 4 < lanes) {
      _mm_storeu_ps(q[i + 4], _mm256_extractf128_ps(t[i], 1));
      _mm_storeu_ps(q[i + 4] + 4, _mm256_extractf128_ps(t[i + 4], 1));
    }
  }
}
[[gnu::always_inline]] inline void load_rows(const void* const rows[kLanes], int offset_floats, FV out[8]) {
  const float* p[kLanes];
  for (int i = 0; i < kLanes; ++i) p[i] = static_cast<const float*>(rows[i]) + offset_floats;
#if PB_SIMD_LANES == 16
  __m256 lo[8], hi[8];
  load_rows8(p, lo);
  load_rows8(p + 8, hi);
  for (int j = 0; j < 8; ++j) out[j] = FV(_mm512_insertf32x8(_mm512_castps256_ps512(lo[j]), hi[j], 1));
#else
  load_rows8(p, reinterpret_cast<__m256*>(out));
#endif
}
// The inverse: lane i of in[j] to rows[i][j], for the first `lanes` rows.
[[gnu::always_inline]] inline void store_rows(const FV in[8], void* const rows[kLanes], int offset_floats, int lanes) {
  float* q[kLanes];
  for (int i = 0; i < kLanes; ++i) q[i] = static_cast<float*>(rows[i]) + offset_floats;
#if PB_SIMD_LANES == 16
  __m256 lo[8], hi[8];
  for (int j = 0; j < 8; ++j) {
    lo[j] = _mm512_castps512_ps256(__m512(in[j]));
    hi[j] = _mm512_extractf32x8_ps(__m512(in[j]), 1);
  }
  store_rows8(lo, q, lanes < 8 ? lanes : 8);
  if (lanes > 8) store_rows8(hi, q + 8, lanes - 8);
#else
  store_rows8(reinterpret_cast<const __m256*>(in), q, lanes);
#endif
}

// Random123's mulhilo32 by a constant, lane-wise: lo and hi words of a * m.
inline void mulhilo(UV a, uint32_t m, UV& lo, UV& hi) {
#if PB_SIMD_LANES == 16
  const __m512i mv = _mm512_set1_epi32(int32_t(m));
  const __m512i even = _mm512_mul_epu32(__m512i(a), mv);                          // even lanes
  const __m512i odd = _mm512_mul_epu32(_mm512_srli_epi64(__m512i(a), 32), mv);  // odd lanes
  lo = UV(_mm512_mask_blend_epi32(0xAAAA, even, _mm512_slli_epi64(odd, 32)));
  hi = UV(_mm512_mask_blend_epi32(0xAAAA, _mm512_srli_epi64(even, 32), odd));
#else
  const __m256i mv = _mm256_set1_epi32(int32_t(m));
  const __m256i even = _mm256_mul_epu32(__m256i(a), mv);                          // lanes 0, 2, 4, 6
  const __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(__m256i(a), 32), mv);  // lanes 1, 3, 5, 7
  lo = UV(_mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xAA));
  hi = UV(_mm256_blend_epi32(_mm256_srli_epi64(even, 32), odd, 0xAA));
#endif
}

// RngStream::draw (rng.h) lane-wise: Philox4x32-10 as Random123 computes it,
// then u32_to_unit_float.
inline void rng_draw(UV pixel, uint64_t seed, UV sample, UV bounce, uint32_t group, FV u[4]) {
  UV c0 = sample, c1 = bounce, c2 = UV{} + group, c3 = UV{} + uint32_t(seed >> 32);
  UV k0 = pixel, k1 = UV{} + uint32_t(seed);
  for (int r = 0; r < 10; ++r) {
    if (r > 0) {
      k0 += 0x9E3779B9u;  // PHILOX_W32_0
      k1 += 0xBB67AE85u;  // PHILOX_W32_1
    }
    UV lo0, hi0, lo1, hi1;
    mulhilo(c0, 0xD2511F53u, lo0, hi0);  // PHILOX_M4x32_0
    mulhilo(c2, 0xCD9E8D57u, lo1, hi1);  // PHILOX_M4x32_1
    c0 = hi1 ^ c1 ^ k0;
    c1 = lo1;
    c2 = hi0 ^ c3 ^ k1;
    c3 = lo0;
  }
  const UV c[4] = {c0, c1, c2, c3};
  for (int j = 0; j < 4; ++j) u[j] = __builtin_convertvector(IV(c[j] >> 8), FV) * (1.0f / 16777216.0f);
}

// sincos_turns<float> (sampling.h) lane-wise, in its order of operations.
inline void sincos_turns(FV u, FV& s, FV& c) {
  const FV x = 4.0f * u;
  const IV q = __builtin_convertvector(x, IV);
  const FV f = x - __builtin_convertvector(q, FV);
  const IV upper = f > 0.5f;
  const FV g = select(upper, 1.0f - f, f);
  const FV y = g * 1.57079632679489662f, y2 = y * y;
  const FV ps = madd(y2, madd(y2, madd(y2, 2.75573192e-6f, -1.98412698e-4f), 8.33333333e-3f), -1.66666667e-1f);
  const FV sp = madd(y * y2, ps, y);
  const FV pc = madd(y2, madd(y2, madd(y2, madd(y2, -2.75573192e-7f, 2.48015873e-5f), -1.38888889e-3f), 4.16666667e-2f), -0.5f);
  const FV cp = madd(y2, pc, 1.0f);
  const FV sa = select(upper, cp, sp), ca = select(upper, sp, cp);
  const IV odd = (q & 1) != 0, half = (q & 2) != 0;
  const FV s1 = select(odd, ca, sa), c1 = select(odd, -sa, ca);
  s = select(half, -s1, s1);
  c = select(half, -c1, c1);
}

inline FV mean3(V3 v) { return (v.x + v.y + v.z) * float(1.0 / 3.0); }

}  // namespace pb::cpu::PB_SIMD_NS
