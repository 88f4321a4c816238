#pragma once
// Direction and point sampling with their densities. Every sampler here is checked
// against its pdf by a chi-square test (tests/unit/test_sampling.cpp).
#include "pathbench/common/math.h"

namespace pb {

// Uniform over the hemisphere around +z: the paper's sampler. pdf = 1 / (2 pi).
template <class T> PB_HD Vec3<T> sample_uniform_hemisphere(T u0, T u1) {
  T z = u0;
  T r = std::sqrt(pmax(T(0), T(1) - z * z));
  T phi = T(2) * kPi<T> * u1;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
template <class T> PB_HD T uniform_hemisphere_pdf() { return T(0.5) * kInvPi<T>; }

// Cosine-weighted over the hemisphere around +z (Malley). pdf = cos / pi.
template <class T> PB_HD Vec3<T> sample_cosine_hemisphere(T u0, T u1) {
  T r = std::sqrt(u0);
  T phi = T(2) * kPi<T> * u1;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(pmax(T(0), T(1) - u0))};
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
  T a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a > T(0) ? a / (a + b) : T(0);
}

}  // namespace pb
