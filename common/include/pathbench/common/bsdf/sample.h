#pragma once
// What every BSDF of the path step returns, in the world frame. Each BSDF is one header
// beside this one (lambert.h, mirror.h, dielectric.h, roughconductor.h): plain
// host+device functions templated on the scalar T, no virtuals; bsdf.h picks one by
// MaterialKind, compiled only for the kinds a render's scene uses.
#include "pathbench/common/math.h"

namespace pb {

// A sampled direction. weight = f cos / pdf (for a delta lobe: the lobe's weight
// divided by the probability of choosing it). pdf is the solid-angle density, and 0
// for a delta lobe: then no other strategy (light sampling) could have produced `wi`,
// and an emitter it hits counts with MIS weight 1.
template <class T> struct BsdfSample {
  Vec3<T> wi;
  Vec3<T> weight;
  T pdf;
};

// f (without the cosine) and the pdf with which the BSDF's own sampler picks `wi`:
// what light sampling needs for its contribution and its MIS weight.
template <class T> struct BsdfEval {
  Vec3<T> f;
  T pdf;
};

// v in the frame's local coordinates (z along the normal).
template <class T> PB_HD Vec3<T> to_local(const Frame<T>& f, Vec3<T> v) { return {fdot(v, f.s), fdot(v, f.t), fdot(v, f.n)}; }

// Mirror reflection of the incoming ray direction d about n (n facing -d).
template <class T> PB_HD Vec3<T> reflect(Vec3<T> d, Vec3<T> n) { return fmadd(n, T(-2) * fdot(d, n), d); }

}  // namespace pb
