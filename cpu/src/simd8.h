// (No include guard: included once per instruction set, see shade_x8.h.)
// Eight float lanes for the CPU wavefront's batched shading (shade_x8.h), written with
// GCC's vector extensions and AVX2 intrinsics: compiled only under
// `#pragma GCC target("avx2")` (render_wavefront.cpp), used only on CPUs that have it. Every operation here is the lane-wise twin of the scalar one the
// path step uses (IEEE +, -, *, /, sqrt, compare-and-select; no FMA, -ffp-contract=off),
// so a lane computes bit for bit what the scalar path step computes for that path.
#include <immintrin.h>

#include <cstdint>
#include <cstring>

#include "pathbench/common/math.h"
#include "pathbench/common/ray_offset.h"

namespace pb::cpu::PB_SIMD_NS {

constexpr int kLanes = 8;
typedef float F8 __attribute__((vector_size(32)));
typedef int32_t I8 __attribute__((vector_size(32)));  // masks: -1 (true) or 0
typedef uint32_t U8 __attribute__((vector_size(32)));

// Three lanes-vectors: math.h's Vec3 operations, lane-wise and in the same order. (Not
// Vec3<F8>: math.h's templates would be instantiated outside the AVX2 region, with the
// baseline calling convention for 32-byte vectors.)
struct V3 {
  F8 x, y, z;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 operator*(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline V3 operator*(V3 a, F8 s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator/(V3 a, F8 s) { return {a.x / s, a.y / s, a.z / s}; }
inline F8 dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

inline F8 splat(float x) { return F8{} + x; }
inline I8 splat_i(int32_t x) { return I8{} + x; }
inline I8 bits(F8 v) { return (I8)v; }  // a cast between vector types of one size keeps the bits
inline F8 from_bits(I8 v) { return (F8)v; }
// m ? a : b per lane (m from a comparison).
inline F8 select(I8 m, F8 a, F8 b) { return m ? a : b; }
inline V3 select(I8 m, V3 a, V3 b) { return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z}; }
// pmin / pmax of math.h, lane-wise: the same comparison picks the same operand (NaN too).
inline F8 vmin(F8 a, F8 b) { return a < b ? a : b; }
inline F8 vmax(F8 a, F8 b) { return a > b ? a : b; }
inline bool any(I8 m) {
  for (int i = 0; i < kLanes; ++i)
    if (m[i]) return true;
  return false;
}

inline F8 sqrt(F8 a) { return F8(_mm256_sqrt_ps(__m256(a))); }
inline F8 abs(F8 a) { return from_bits(bits(a) & 0x7fffffff); }
inline F8 copysign(F8 mag, F8 sign) { return from_bits((bits(mag) & 0x7fffffff) | (bits(sign) & int32_t(0x80000000u))); }

// As math.h: a * (1 / length(a)).
inline V3 normalize(V3 a) { return a * (1.0f / sqrt(dot(a, a))); }

// Frame<T>::from_normal (math.h), lane-wise, in the same order of operations.
struct Frame8 {
  V3 s, t, n;
  static Frame8 from_normal(V3 n) {
    const F8 sign = copysign(splat(1.0f), n.z);
    const F8 a = -1.0f / (sign + n.z);
    const F8 b = n.x * n.y * a;
    return {{1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x}, {b, sign + n.y * n.y * a, -n.y}, n};
  }
  V3 to_world(V3 v) const { return s * v.x + t * v.y + n * v.z; }
};

// offset_ray_origin (ray_offset.h) lane-wise: the float-grid move along n.
inline F8 offset_coord(F8 pc, F8 nc, const RayOffset& off) {
  const F8 near_moved = pc + off.fixed_distance * nc;
  const I8 of = __builtin_convertvector(256.0f * nc, I8);  // truncation, as int32_t(float)
  const I8 far_bits = bits(pc) + ((pc < 0.0f) ? -of : of);
  return select(abs(pc) < off.near_origin, near_moved, from_bits(far_bits));
}
inline V3 offset_ray_origin(V3 p, V3 n, const RayOffset& off) {
  return {offset_coord(p.x, n.x, off), offset_coord(p.y, n.y, off), offset_coord(p.z, n.z, off)};
}

// power_heuristic (sampling.h) lane-wise.
inline F8 power_heuristic(F8 pdf_a, F8 pdf_b) {
  const F8 a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return select(a > 0.0f, a / (a + b), splat(0.0f));
}

// Eight 8-float records ("rows") to lanes and back: lane i of out[j] is rows[i][j].
// Each 4x4 block is transposed inside a 128-bit half; the halves come straight from
// memory (rows i and i + 4 share a register), so the whole load is 16 loads and 16
// shuffles.
[[gnu::always_inline]] inline void transpose4_halves(__m256 r0, __m256 r1, __m256 r2, __m256 r3, F8* out) {
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  out[0] = F8(_mm256_shuffle_ps(t0, t2, 0x44));
  out[1] = F8(_mm256_shuffle_ps(t0, t2, 0xEE));
  out[2] = F8(_mm256_shuffle_ps(t1, t3, 0x44));
  out[3] = F8(_mm256_shuffle_ps(t1, t3, 0xEE));
}
[[gnu::always_inline]] inline __m256 two_halves(const float* lo, const float* hi) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1);
}
[[gnu::always_inline]] inline void load_rows(const void* const rows[8], int offset_floats, F8 out[8]) {
  const float* p[8];
  for (int i = 0; i < 8; ++i) p[i] = static_cast<const float*>(rows[i]) + offset_floats;
  transpose4_halves(two_halves(p[0], p[4]), two_halves(p[1], p[5]), two_halves(p[2], p[6]), two_halves(p[3], p[7]), out);
  transpose4_halves(two_halves(p[0] + 4, p[4] + 4), two_halves(p[1] + 4, p[5] + 4), two_halves(p[2] + 4, p[6] + 4),
                    two_halves(p[3] + 4, p[7] + 4), out + 4);
}
// The inverse: lane i of in[j] to rows[i][j], for the first `lanes` rows.
[[gnu::always_inline]] inline void store_rows(const F8 in[8], void* const rows[8], int offset_floats, int lanes) {
  F8 t[8];
  transpose4_halves(__m256(in[0]), __m256(in[1]), __m256(in[2]), __m256(in[3]), t);
  transpose4_halves(__m256(in[4]), __m256(in[5]), __m256(in[6]), __m256(in[7]), t + 4);
  // t[i] (i < 4): row i, columns 0-3 | row i + 4, columns 0-3; t[i + 4]: the same for columns 4-7.
  for (int i = 0; i < 4; ++i) {
    if (i < lanes) {
      float* q = static_cast<float*>(rows[i]) + offset_floats;
      _mm_storeu_ps(q, _mm256_castps256_ps128(__m256(t[i])));
      _mm_storeu_ps(q + 4, _mm256_castps256_ps128(__m256(t[i + 4])));
    }
    if (i + 4 < lanes) {
      float* q = static_cast<float*>(rows[i + 4]) + offset_floats;
      _mm_storeu_ps(q, _mm256_extractf128_ps(__m256(t[i]), 1));
      _mm_storeu_ps(q + 4, _mm256_extractf128_ps(__m256(t[i + 4]), 1));
    }
  }
}

// Random123's mulhilo32 by a constant, eight lanes: lo and hi words of a * m.
inline void mulhilo(U8 a, uint32_t m, U8& lo, U8& hi) {
  const __m256i mv = _mm256_set1_epi32(int32_t(m));
  const __m256i even = _mm256_mul_epu32(__m256i(a), mv);                          // lanes 0, 2, 4, 6
  const __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(__m256i(a), 32), mv);  // lanes 1, 3, 5, 7
  lo = U8(_mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xAA));
  hi = U8(_mm256_blend_epi32(_mm256_srli_epi64(even, 32), odd, 0xAA));
}

// RngStream::draw (rng.h) for eight lanes: Philox4x32-10 as Random123 computes it,
// then u32_to_unit_float.
inline void rng_draw(U8 pixel, uint64_t seed, U8 sample, U8 bounce, uint32_t group, F8 u[4]) {
  U8 c0 = sample, c1 = bounce, c2 = U8{} + group, c3 = U8{} + uint32_t(seed >> 32);
  U8 k0 = pixel, k1 = U8{} + uint32_t(seed);
  for (int r = 0; r < 10; ++r) {
    if (r > 0) {
      k0 += 0x9E3779B9u;  // PHILOX_W32_0
      k1 += 0xBB67AE85u;  // PHILOX_W32_1
    }
    U8 lo0, hi0, lo1, hi1;
    mulhilo(c0, 0xD2511F53u, lo0, hi0);  // PHILOX_M4x32_0
    mulhilo(c2, 0xCD9E8D57u, lo1, hi1);  // PHILOX_M4x32_1
    c0 = hi1 ^ c1 ^ k0;
    c1 = lo1;
    c2 = hi0 ^ c3 ^ k1;
    c3 = lo0;
  }
  const U8 c[4] = {c0, c1, c2, c3};
  for (int j = 0; j < 4; ++j) u[j] = __builtin_convertvector(I8(c[j] >> 8), F8) * (1.0f / 16777216.0f);
}

// sincos_turns<float> (sampling.h) lane-wise, in its order of operations.
inline void sincos_turns(F8 u, F8& s, F8& c) {
  const F8 x = 4.0f * u;
  const I8 q = __builtin_convertvector(x, I8);
  const F8 f = x - __builtin_convertvector(q, F8);
  const I8 upper = f > 0.5f;
  const F8 g = select(upper, 1.0f - f, f);
  const F8 y = g * 1.57079632679489662f, y2 = y * y;
  const F8 sp = y + y * y2 * (-1.66666667e-1f + y2 * (8.33333333e-3f + y2 * (-1.98412698e-4f + y2 * 2.75573192e-6f)));
  const F8 cp = 1.0f + y2 * (-0.5f + y2 * (4.16666667e-2f + y2 * (-1.38888889e-3f + y2 * (2.48015873e-5f + y2 * -2.75573192e-7f))));
  const F8 sa = select(upper, cp, sp), ca = select(upper, sp, cp);
  const I8 odd = (q & 1) != 0, half = (q & 2) != 0;
  const F8 s1 = select(odd, ca, sa), c1 = select(odd, -sa, ca);
  s = select(half, -s1, s1);
  c = select(half, -c1, c1);
}

inline F8 mean3(V3 v) { return (v.x + v.y + v.z) * float(1.0 / 3.0); }

}  // namespace pb::cpu::PB_SIMD_NS
