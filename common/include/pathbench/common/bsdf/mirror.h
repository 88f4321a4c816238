#pragma once
// Perfect mirror: Mitsuba's `conductor` with material "none" (eta 0, k 1, whose
// Fresnel reflectance is exactly 1) times specular_reflectance = albedo; two-sided.
// A delta lobe: sampled only, never evaluated.
#include "pathbench/common/bsdf/sample.h"

namespace pb {

// d: the incoming ray's direction; n: the normal on d's side (dot(d, n) <= 0).
template <class T> PB_HD BsdfSample<T> mirror_sample(Vec3f albedo, Vec3<T> d, Vec3<T> n) {
  return {reflect(d, n), Vec3<T>(albedo), T(0)};
}

}  // namespace pb
