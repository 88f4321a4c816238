#pragma once
// Direction and point sampling with their densities. Every sampler here is checked
// against its pdf by a chi-square test (tests/unit/test_sampling.cpp).
#include <cstdint>

#include "pathbench/common/math.h"

namespace pb {

// sin and cos of the angle 2 pi u, for u in [0, 1) (a turn fraction, as the samplers
// draw it). In float: the quarter turn and the octant come exactly from u (4u and
// 1 - f are exact in float), then Taylor polynomials on [0, pi/4] (truncation below
// 2e-9; a few float ulps in all, like computing 2 pi u in float before a libm call).
// No libm call, branch-free, and the same operations lane for lane in the CPU
// wavefront's batched shading (cpu/src/simd8.h), which must match it bit for bit.
// In double: the libm functions (the precision study wants double's full accuracy).
template <class T> PB_HD void sincos_turns(T u, T& s, T& c) {
  if constexpr (sizeof(T) == sizeof(float)) {
    const float x = 4.0f * u;
    const int32_t q = int32_t(x);     // quarter turns, 0..3
    const float f = x - float(q);     // [0, 1) of the quarter
    const bool upper = f > 0.5f;
    const float g = upper ? 1.0f - f : f;  // [0, 0.5]
    const float y = g * 1.57079632679489662f, y2 = y * y;
    // Horner in fused steps (fmadd), as the vector twin does.
    const float ps = fmadd(y2, fmadd(y2, fmadd(y2, 2.75573192e-6f, -1.98412698e-4f), 8.33333333e-3f), -1.66666667e-1f);
    const float sp = fmadd(y * y2, ps, y);
    const float pc = fmadd(y2, fmadd(y2, fmadd(y2, fmadd(y2, -2.75573192e-7f, 2.48015873e-5f), -1.38888889e-3f), 4.16666667e-2f), -0.5f);
    const float cp = fmadd(y2, pc, 1.0f);
    const float sa = upper ? cp : sp, ca = upper ? sp : cp;  // of the angle f pi / 2
    const float s1 = (q & 1) ? ca : sa, c1 = (q & 1) ? -sa : ca;
    s = (q & 2) ? -s1 : s1;
    c = (q & 2) ? -c1 : c1;
  } else {
    const T phi = T(2) * kPi<T> * u;
    s = std::sin(phi);
    c = std::cos(phi);
  }
}

// Uniform over the hemisphere around +z: the paper's sampler. pdf = 1 / (2 pi).
template <class T> PB_HD Vec3<T> sample_uniform_hemisphere(T u0, T u1) {
  T z = u0;
  T r = std::sqrt(pmax(T(0), fmadd(-z, z, T(1))));
  T sin_phi, cos_phi;
  sincos_turns(u1, sin_phi, cos_phi);
  return {r * cos_phi, r * sin_phi, z};
}
template <class T> PB_HD T uniform_hemisphere_pdf() { return T(0.5) * kInvPi<T>; }

// Cosine-weighted over the hemisphere around +z (Malley). pdf = cos / pi.
template <class T> PB_HD Vec3<T> sample_cosine_hemisphere(T u0, T u1) {
  T r = std::sqrt(u0);
  T sin_phi, cos_phi;
  sincos_turns(u1, sin_phi, cos_phi);
  return {r * cos_phi, r * sin_phi, std::sqrt(pmax(T(0), T(1) - u0))};
}
template <class T> PB_HD T cosine_hemisphere_pdf(T cos_theta) { return pmax(cos_theta, T(0)) * kInvPi<T>; }

// Uniform point on a triangle, as barycentrics (b1, b2); pdf = 1 / area.
template <class T> struct Barycentrics {
  T b1, b2;
};
template <class T> PB_HD Barycentrics<T> sample_uniform_triangle(T u0, T u1) {
  T su = std::sqrt(u0);
  return {T(1) - su, u1 * su};
}

// Power heuristic with beta = 2 (Veach 1997) for two strategies of one sample each.
template <class T> PB_HD T power_heuristic(T pdf_a, T pdf_b) {
  T a = pdf_a * pdf_a;
  return a > T(0) ? a / fmadd(pdf_b, pdf_b, a) : T(0);
}

}  // namespace pb
