#pragma once
// The BSDF of a material, by kind, for the material kinds `Kinds` a render is compiled
// for (features.h): kinds outside `Kinds` cost nothing, and with a single kind there is
// no dispatch at all.
#include "pathbench/common/bsdf/dielectric.h"
#include "pathbench/common/bsdf/lambert.h"
#include "pathbench/common/bsdf/mirror.h"
#include "pathbench/common/bsdf/roughconductor.h"
#include "pathbench/common/features.h"
#include "pathbench/common/rng.h"

namespace pb {

// True where the BSDF has a delta lobe only (light sampling cannot help there).
template <uint32_t Kinds> PB_HD bool bsdf_is_delta(const Material& m) {
  if constexpr ((Kinds & kDeltaKinds) == 0) return false;
  else return is_kind<Kinds, MaterialKind::Mirror>(m) || is_kind<Kinds, MaterialKind::Dielectric>(m);
}

// f and pdf towards `wi` (world, unit), for a non-delta material seen from direction d
// (the incoming ray's) with the normal n on d's side; cos_i = dot(n, wi) > 0.
template <uint32_t Kinds, class T>
PB_HD BsdfEval<T> bsdf_eval(const Material& m, const Frame<T>& frame, Vec3<T> d, Vec3<T> wi, T cos_i) {
  if constexpr (has_kind<Kinds>(MaterialKind::RoughConductor))
    if (is_kind<Kinds, MaterialKind::RoughConductor>(m))
      return roughconductor_eval(m.albedo, T(m.alpha), to_local(frame, -d), to_local(frame, wi));
  return lambert_eval<T>(m.albedo, cos_i);
}

// Samples the next direction at a hit seen along d; n is the normal on d's side, and
// `front` says whether d hit the geometric normal's side. Returns false when the
// sample carries nothing (the path ends).
template <uint32_t Kinds, class T>
PB_HD bool bsdf_sample(const Material& m, Sampling sampling, const Frame<T>& frame, Vec3<T> d, bool front,
                       const Uniform4& u, BsdfSample<T>& bs) {
  if (is_kind<Kinds, MaterialKind::Diffuse>(m)) return lambert_sample(m.albedo, sampling, frame, T(u.v[0]), T(u.v[1]), bs);
  if (is_kind<Kinds, MaterialKind::Mirror>(m)) {
    bs = mirror_sample(m.albedo, d, frame.n);
    return true;
  }
  if (is_kind<Kinds, MaterialKind::Dielectric>(m)) {
    bs = dielectric_sample(m.albedo, m.ior, front, d, frame.n, T(u.v[0]));
    return true;
  }
  if (is_kind<Kinds, MaterialKind::RoughConductor>(m))
    return roughconductor_sample(m.albedo, T(m.alpha), frame, to_local(frame, -d), T(u.v[0]), T(u.v[1]), bs);
  return false;
}

}  // namespace pb
