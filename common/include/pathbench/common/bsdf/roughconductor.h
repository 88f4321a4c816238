#pragma once
// Rough conductor: Mitsuba's `roughconductor` with distribution "ggx", isotropic
// `alpha`, material "none" (Fresnel reflectance 1) times specular_reflectance = albedo,
// sample_visible = true; two-sided (the normal faces the incoming ray). Its
// definitions, exactly:
//   D(m)      = 1 / (pi a^2 (m.x^2/a^2 + m.y^2/a^2 + m.z^2)^2)           (GGX)
//   G1(v, m)  = 2 / (1 + sqrt(1 + a^2 tan^2 theta_v)), 0 if v sees m's back
//   G         = G1(wo, m) G1(wi, m)                    (separable Smith)
//   f         = albedo D G / (4 cos_o cos_i),  m = normalize(wo + wi)
//   pdf(wi)   = D(m) G1(wo, m) / (4 cos_o)             (visible normals, reflected)
//   sample weight f cos_i / pdf = albedo G1(wi, m)
// All in the local frame (z = the normal on the incoming side); wo points away from the
// surface towards where the ray came from.
#include "pathbench/common/bsdf/sample.h"
#include "pathbench/common/sampling.h"

namespace pb {

template <class T> PB_HD T ggx_d(T alpha, Vec3<T> m) {
  const T a2 = alpha * alpha;
  const T k = fmadd(m.z, m.z, fmadd(m.x, m.x, m.y * m.y) / a2);
  const T d = T(1) / (kPi<T> * a2 * k * k);
  return d * m.z > T(1e-20) ? d : T(0);
}

template <class T> PB_HD T ggx_g1(T alpha, Vec3<T> v, Vec3<T> m) {
  if (fdot(v, m) * v.z <= T(0)) return T(0);
  const T xy2 = alpha * alpha * fmadd(v.x, v.x, v.y * v.y);
  if (xy2 == T(0)) return T(1);
  return T(2) / (T(1) + std::sqrt(T(1) + xy2 / (v.z * v.z)));
}

// A normal of the GGX distribution seen from wo (Heitz 2018, "Sampling the GGX
// Distribution of Visible Normals"): density D_wo(m) = G1(wo, m) max(0, wo.m) D(m) / wo.z.
template <class T> PB_HD Vec3<T> ggx_sample_visible_normal(T alpha, Vec3<T> wo, T u0, T u1) {
  const Vec3<T> vh = fnormalize(Vec3<T>{alpha * wo.x, alpha * wo.y, wo.z});
  const T len2 = fmadd(vh.x, vh.x, vh.y * vh.y);
  const Vec3<T> t1 = len2 > T(0) ? Vec3<T>{-vh.y, vh.x, T(0)} * (T(1) / std::sqrt(len2)) : Vec3<T>{T(1), T(0), T(0)};
  const Vec3<T> t2 = fcross(vh, t1);
  const T r = std::sqrt(u0);
  // sincos_turns, not std::sin/std::cos of 2 pi u1: the CPU's libm and CUDA's sinf/cosf
  // round differently, and the GPU's samples must be the CPU's bit for bit.
  T sin_phi, cos_phi;
  sincos_turns(u1, sin_phi, cos_phi);
  const T p1 = r * cos_phi;
  const T s = T(0.5) * (T(1) + vh.z);
  const T p2 = fmadd(T(1) - s, std::sqrt(pmax(T(0), fmadd(-p1, p1, T(1)))), s * (r * sin_phi));
  const Vec3<T> nh = fmadd(t2, p2, fmadd(t1, p1, vh * std::sqrt(pmax(T(0), fmadd(-p2, p2, fmadd(-p1, p1, T(1)))))));
  return fnormalize(Vec3<T>{alpha * nh.x, alpha * nh.y, pmax(T(0), nh.z)});
}

template <class T> PB_HD BsdfEval<T> roughconductor_eval(Vec3f albedo, T alpha, Vec3<T> wo, Vec3<T> wi) {
  if (!(wo.z > T(0)) || !(wi.z > T(0))) return {{T(0), T(0), T(0)}, T(0)};
  const Vec3<T> m = fnormalize(wo + wi);
  const T d = ggx_d(alpha, m);
  const T g1o = ggx_g1(alpha, wo, m);
  const T f = d * g1o * ggx_g1(alpha, wi, m) / (T(4) * wo.z * wi.z);
  return {Vec3<T>(albedo) * f, d * g1o / (T(4) * wo.z)};
}

// Returns false when the reflected direction falls below the surface (no contribution).
template <class T>
PB_HD bool roughconductor_sample(Vec3f albedo, T alpha, const Frame<T>& frame, Vec3<T> wo, T u0, T u1,
                                 BsdfSample<T>& bs) {
  if (!(wo.z > T(0))) return false;
  const Vec3<T> m = ggx_sample_visible_normal(alpha, wo, u0, u1);
  const Vec3<T> wi = fmadd(m, T(2) * fdot(wo, m), -wo);
  if (!(wi.z > T(0))) return false;
  const T d = ggx_d(alpha, m);
  bs.pdf = d * ggx_g1(alpha, wo, m) / (T(4) * wo.z);
  if (!(bs.pdf > T(0))) return false;
  bs.weight = Vec3<T>(albedo) * ggx_g1(alpha, wi, m);
  bs.wi = frame.to_world(wi);
  return true;
}

}  // namespace pb
