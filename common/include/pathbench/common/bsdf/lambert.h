#pragma once
// Two-sided Lambertian reflector, f = albedo / pi (Mitsuba's `diffuse` inside
// `twosided`). Directions come from the uniform hemisphere (the paper's sampler) or
// the cosine-weighted one, as the render's Sampling asks.
#include "pathbench/common/bsdf/sample.h"
#include "pathbench/common/sampling.h"
#include "pathbench/common/settings.h"

namespace pb {

template <class T> PB_HD Vec3<T> lambert_f(Vec3f albedo) { return Vec3<T>(albedo) * kInvPi<T>; }

// For light sampling, whose MIS partner is BSDF sampling: always cosine-weighted
// (light sampling happens only with Sampling::Nee, which samples the BSDF by cosine).
template <class T> PB_HD BsdfEval<T> lambert_eval(Vec3f albedo, T cos_i) {
  return {lambert_f<T>(albedo), cosine_hemisphere_pdf(cos_i)};
}

// Returns false where the direction carries nothing (grazing, zero pdf).
template <class T>
PB_HD bool lambert_sample(Vec3f albedo, Sampling sampling, const Frame<T>& frame, T u0, T u1, BsdfSample<T>& bs) {
  Vec3<T> local;
  T pdf;
  if (sampling == Sampling::Uniform) {
    local = sample_uniform_hemisphere(u0, u1);
    pdf = uniform_hemisphere_pdf<T>();
  } else {
    local = sample_cosine_hemisphere(u0, u1);
    pdf = cosine_hemisphere_pdf(local.z);
  }
  if (!(pdf > T(0)) || !(local.z > T(0))) return false;
  // f cos / pdf in closed form: (albedo / pi) cos / (1 / 2 pi) = albedo 2 cos for the
  // uniform hemisphere, (albedo / pi) cos / (cos / pi) = albedo for the cosine one.
  bs.weight = sampling == Sampling::Uniform ? Vec3<T>(albedo) * (T(2) * local.z) : Vec3<T>(albedo);
  bs.wi = frame.to_world(local);
  bs.pdf = pdf;
  return true;
}

}  // namespace pb
