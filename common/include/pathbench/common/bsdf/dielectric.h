#pragma once
// Smooth dielectric (glass): Mitsuba's `dielectric` with int_ior = ior, ext_ior = 1,
// specular_reflectance = specular_transmittance = albedo. One random number chooses
// reflection with probability F (the Fresnel reflectance) and refraction otherwise,
// so both weights are the albedo; refraction also scales radiance by 1 / eta^2 (the
// solid angle compresses), as Mitsuba does in radiance transport. Two-sided: the ray
// enters the glass when it hits the front (geometric-normal) side and leaves it when it
// hits the back, so closed meshes are solid glass whatever their winding inside.
#include "pathbench/common/bsdf/mirror.h"
#include "pathbench/common/bsdf/sample.h"

namespace pb {

template <class T> struct Fresnel {
  T reflectance;  // unpolarised, 1 under total internal reflection
  T cos_t;        // cosine of the transmitted direction with the normal (>= 0)
};

// Mitsuba's fresnel(): cos_i = |cosine| of the incident direction, eta = eta_t / eta_i
// (the relative index of the side being entered).
template <class T> PB_HD Fresnel<T> fresnel_dielectric(T cos_i, T eta) {
  const T eta_ti = T(1) / eta;
  const T cos_t2 = fmadd(-fmadd(-cos_i, cos_i, T(1)), eta_ti * eta_ti, T(1));
  if (!(cos_t2 > T(0))) return {T(1), T(0)};  // total internal reflection
  const T cos_t = std::sqrt(cos_t2);
  if (eta == T(1)) return {T(0), cos_t};      // index-matched: no interface
  if (cos_i == T(0)) return {T(1), cos_t};    // grazing
  const T a_s = fmadd(-eta, cos_t, cos_i) / fmadd(eta, cos_t, cos_i);
  const T a_p = fmadd(-eta, cos_i, cos_t) / fmadd(eta, cos_i, cos_t);
  return {T(0.5) * fmadd(a_s, a_s, a_p * a_p), cos_t};
}

// d: incoming direction; n: the normal on d's side; entering: d hit the front side.
// u: one uniform number. The sampled direction lies below n when refracted.
template <class T>
PB_HD BsdfSample<T> dielectric_sample(Vec3f albedo, float ior, bool entering, Vec3<T> d, Vec3<T> n, T u) {
  const T eta = entering ? T(ior) : T(1) / T(ior);
  const T cos_i = pmin(-fdot(d, n), T(1));
  const Fresnel<T> fr = fresnel_dielectric(cos_i, eta);
  if (u < fr.reflectance) return mirror_sample(albedo, d, n);
  const T eta_ti = T(1) / eta;
  const Vec3<T> wt = fnormalize(fmadd(d, eta_ti, n * fmadd(eta_ti, cos_i, -fr.cos_t)));
  return {wt, Vec3<T>(albedo) * (eta_ti * eta_ti), T(0)};
}

}  // namespace pb
