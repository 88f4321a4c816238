#pragma once
// Small vector type templated on the scalar (float or double): the path step, the
// sampling and the intersection code are all written against Vec3<T>.
#include <cmath>
#include <cstdint>
#include <type_traits>

#include "pathbench/common/hd.h"

namespace pb {

template <class T> constexpr T kPi = T(3.14159265358979323846);
template <class T> constexpr T kInvPi = T(0.31830988618379067154);

template <class T> struct Vec3 {
  T x, y, z;
  Vec3() = default;  // trivial: uninitialised, or zero with Vec3{}
  PB_HD constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
  // Between precisions only explicitly: Vec3<double>(a_float_vector). A constructor,
  // not a conversion operator: with C++20's parenthesised aggregate initialisation
  // some front ends (nvcc emulating g++ 13) read Vec3<double>(v) as {x = v}.
  template <class U> PB_HD explicit constexpr Vec3(const Vec3<U>& v) : x(T(v.x)), y(T(v.y)), z(T(v.z)) {}
  PB_HD T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  PB_HD T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <class T> PB_HD Vec3<T> operator+(Vec3<T> a, Vec3<T> b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class T> PB_HD Vec3<T> operator-(Vec3<T> a, Vec3<T> b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class T> PB_HD Vec3<T> operator-(Vec3<T> a) { return {-a.x, -a.y, -a.z}; }
template <class T> PB_HD Vec3<T> operator*(Vec3<T> a, Vec3<T> b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
template <class T> PB_HD Vec3<T> operator*(Vec3<T> a, T s) { return {a.x * s, a.y * s, a.z * s}; }
template <class T> PB_HD Vec3<T> operator*(T s, Vec3<T> a) { return {a.x * s, a.y * s, a.z * s}; }
template <class T> PB_HD Vec3<T> operator/(Vec3<T> a, T s) { return {a.x / s, a.y / s, a.z / s}; }
template <class T> PB_HD Vec3<T>& operator+=(Vec3<T>& a, Vec3<T> b) { a = a + b; return a; }
template <class T> PB_HD Vec3<T>& operator*=(Vec3<T>& a, Vec3<T> b) { a = a * b; return a; }
template <class T> PB_HD Vec3<T>& operator*=(Vec3<T>& a, T s) { a = a * s; return a; }

// a * b + c with one rounding, the same bits on every device: fmaf / fma on the GPU,
// the FMA instruction on a host compiled for it (-mfma, -march=native). In a portable
// x86-64 build (SSE2 baseline) the FMA instruction inline where the CPU has it, checked
// once at start-up (a predicted branch: std::fma alone is a call into libm per use, whose
// spills made the scalar path step 11% more instructions), else std::fma (libm, correctly
// rounded: the same bits). The path step uses it where a multiply feeds an add; the CPU's
// vector path step (cpu/src/simd8.h) fuses exactly the same operations, so its lanes keep
// the scalar bits. Never left to the compiler: -ffp-contract=off and --fmad=false.
#if !defined(__CUDA_ARCH__) && !defined(__FMA__) && defined(__x86_64__) && defined(__GNUC__)
#define PB_HOST_FMA_DISPATCH 1
namespace detail {
// False until set during static initialisation (a use before that takes std::fma).
inline const bool kHostHasFma = [] {
  __builtin_cpu_init();
  return __builtin_cpu_supports("fma") != 0;
}();
}  // namespace detail
#endif
PB_HD float fmadd(float a, float b, float c) {
#if defined(__CUDA_ARCH__)
  return fmaf(a, b, c);
#elif defined(__FMA__)
  return __builtin_fmaf(a, b, c);
#elif defined(PB_HOST_FMA_DISPATCH)
  if (__builtin_expect(detail::kHostHasFma, 1)) {
    __asm__("vfmadd213ss %2, %1, %0" : "+x"(a) : "x"(b), "x"(c));  // a = b * a + c
    return a;
  }
  return std::fma(a, b, c);
#else
  return std::fma(a, b, c);
#endif
}
PB_HD double fmadd(double a, double b, double c) {
#if defined(__CUDA_ARCH__)
  return fma(a, b, c);
#elif defined(__FMA__)
  return __builtin_fma(a, b, c);
#elif defined(PB_HOST_FMA_DISPATCH)
  if (__builtin_expect(detail::kHostHasFma, 1)) {
    __asm__("vfmadd213sd %2, %1, %0" : "+x"(a) : "x"(b), "x"(c));
    return a;
  }
  return std::fma(a, b, c);
#else
  return std::fma(a, b, c);
#endif
}
template <class T> PB_HD Vec3<T> fmadd(Vec3<T> a, T s, Vec3<T> c) {  // a * s + c
  return {fmadd(a.x, s, c.x), fmadd(a.y, s, c.y), fmadd(a.z, s, c.z)};
}

template <class T> PB_HD T dot(Vec3<T> a, Vec3<T> b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> PB_HD Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class T> PB_HD T length(Vec3<T> a) { return std::sqrt(dot(a, a)); }
template <class T> PB_HD Vec3<T> normalize(Vec3<T> a) { return a * (T(1) / length(a)); }
// The path step's dot, cross and normalize, fused (fmadd): two roundings fewer per dot
// product, one per cross component. dot / cross / normalize above stay unfused for the
// scene build and the triangle tests, whose arithmetic is not the path step's.
template <class T> PB_HD T fdot(Vec3<T> a, Vec3<T> b) { return fmadd(a.x, b.x, fmadd(a.y, b.y, a.z * b.z)); }
template <class T> PB_HD Vec3<T> fcross(Vec3<T> a, Vec3<T> b) {
  return {fmadd(a.y, b.z, -(a.z * b.y)), fmadd(a.z, b.x, -(a.x * b.z)), fmadd(a.x, b.y, -(a.y * b.x))};
}
template <class T> PB_HD Vec3<T> fnormalize(Vec3<T> a) { return a * (T(1) / std::sqrt(fdot(a, a))); }
template <class T> PB_HD T pmin(T a, T b) { return a < b ? a : b; }
template <class T> PB_HD T pmax(T a, T b) { return a > b ? a : b; }
template <class T> PB_HD T max_component(Vec3<T> a) { return pmax(a.x, pmax(a.y, a.z)); }
template <class T> PB_HD Vec3<T> vmin(Vec3<T> a, Vec3<T> b) { return {pmin(a.x, b.x), pmin(a.y, b.y), pmin(a.z, b.z)}; }
template <class T> PB_HD Vec3<T> vmax(Vec3<T> a, Vec3<T> b) { return {pmax(a.x, b.x), pmax(a.y, b.y), pmax(a.z, b.z)}; }
template <class T> PB_HD Vec3<T> vabs(Vec3<T> a) { return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}; }
template <class T> PB_HD bool is_zero(Vec3<T> a) { return a.x == T(0) && a.y == T(0) && a.z == T(0); }
template <class T> PB_HD bool is_finite(Vec3<T> a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
template <class T> PB_HD T luminance(Vec3<T> c) { return T(0.2126) * c.x + T(0.7152) * c.y + T(0.0722) * c.z; }

// Orthonormal basis around a unit vector n (Duff et al. 2017, branchless).
template <class T> struct Frame {
  Vec3<T> s, t, n;
  PB_HD static Frame from_normal(Vec3<T> n) {
    T sign = std::copysign(T(1), n.z);
    T a = T(-1) / (sign + n.z);
    T b = n.x * n.y * a;
    return {{fmadd(n.x * n.x, sign * a, T(1)), sign * b, -sign * n.x}, {b, fmadd(n.y * n.y, a, sign), -n.y}, n};
  }
  PB_HD Vec3<T> to_world(Vec3<T> v) const { return fmadd(s, v.x, fmadd(t, v.y, n * v.z)); }
};

}  // namespace pb
