#pragma once
// The path step, written once for every tracer and device. A tracer only
//   1. starts a path with path_begin,
//   2. finds the triangle its ray hits (path ends on a miss),
//   3. calls path_hit with that hit, which adds emission, may ask for one shadow
//      ray, samples the next direction and applies Russian roulette,
//   4. traces the shadow ray, if any, and calls shadow_unoccluded when it is clear,
//   5. loops to 2 while path_hit says Continue, then hands the path's L to the film.
// At the last vertex of a bounded path a tracer may replace 2-4 with path_final_query
// and one occlusion test (below).
// Everything random comes from the (seed, pixel, sample, bounce) stream, so the order
// in which a tracer runs these steps across paths cannot change the image.
//
// path_hit and path_final_query take the material kinds they are compiled for as a
// leading template argument (features.h: a tracer dispatches once per render with
// with_features); the default, every kind this build has, is right for any scene.
#include <cstdint>

#include "pathbench/common/bsdf/bsdf.h"
#include "pathbench/common/camera.h"
#include "pathbench/common/features.h"
#include "pathbench/common/ray_offset.h"
#include "pathbench/common/rng.h"
#include "pathbench/common/sampling.h"
#include "pathbench/common/scene.h"
#include "pathbench/common/settings.h"
#include "pathbench/common/surface_hit.h"
#include "pathbench/common/watertight.h"

namespace pb {

template <class T> struct PathState {
  Ray<T> ray;
  Vec3<T> beta;      // path throughput
  Vec3<T> L;         // radiance gathered so far
  T bsdf_pdf;        // solid-angle pdf with which ray.d was sampled (for MIS); 0 after a
                     // delta bounce (mirror, glass), which light sampling cannot reproduce
  uint32_t pixel;
  uint32_t sample;
  uint32_t depth;    // scattering events so far (every bounce, delta ones included)
};

// A shadow ray from a shading point to a point on an emitter: the emitter is visible
// when nothing is hit for t in (0, 1) along the unnormalised direction.
template <class T> struct ShadowQuery {
  Ray<T> ray;
  Vec3<T> contribution;  // added to the path's radiance if unoccluded
};

enum class PathEvent : uint32_t { Continue = 0, Done = 1 };

template <class T> PB_HD T mean3(Vec3<T> v) { return (v.x + v.y + v.z) * T(1.0 / 3.0); }

template <class T>
PB_HD void path_begin(const SceneView& s, const PathConfig& c, uint32_t pixel, uint32_t sample,
                      PathState<T>& st) {
  const Uniform4 u = RngStream{pixel, c.seed}.draw(sample, 0, kRngCamera);
  st.ray = camera_ray<T>(s.camera, pixel % c.width, pixel / c.width, c.width, c.height, u.v[0], u.v[1]);
  st.beta = {T(1), T(1), T(1)};
  st.L = {T(0), T(0), T(0)};
  st.bsdf_pdf = T(0);
  st.pixel = pixel;
  st.sample = sample;
  st.depth = 0;
}

// Area density of light sampling at a point of an emitter with emission `Le`:
// emitters are chosen in proportion to area * mean(Le), then a point uniformly.
template <class T> PB_HD T emitter_area_pdf(const SceneView& s, Vec3f Le) {
  return T(mean3(Le)) / T(s.emitter_power_total);
}

// Index of the emitter whose CDF interval holds u (binary search). `u` is then
// rescaled to [0, 1) within that interval, so the same number can place the point on
// the emitter (sample reuse: one dimension fewer per vertex, stratification kept).
PB_HD uint32_t pick_emitter(const SceneView& s, float& u) {
  uint32_t lo = 0, hi = s.num_emitters - 1;
  while (lo < hi) {
    uint32_t mid = (lo + hi) / 2;
    if (u < s.emitter_cdf[mid]) hi = mid; else lo = mid + 1;
  }
  const float below = lo > 0 ? s.emitter_cdf[lo - 1] : 0.0f;
  const float width = s.emitter_cdf[lo] - below;
  u = width > 0.0f ? pmin((u - below) / width, 0x1.fffffep-1f) : 0.0f;
  return lo;
}

// What the path gains from emission `Le` seen at hit `h` (front side, cosine cos_o):
// beta Le, weighted by MIS against light sampling when that could have found it too.
// After a delta bounce (bsdf_pdf 0) light sampling could not have found it: weight 1.
template <uint32_t Kinds, class T>
PB_HD Vec3<T> emitted_radiance(const SceneView& s, const PathConfig& c, const PathState<T>& st, const SurfaceHit<T>& h,
                               Vec3f Le, T cos_o) {
  T w = T(1);
  bool mis = c.sampling == Sampling::Nee && st.depth > 0;
  if constexpr ((Kinds & kDeltaKinds) != 0) mis = mis && st.bsdf_pdf > T(0);
  if (mis) {
    // power_heuristic(bsdf_pdf, pdf_light) with pdf_light = area_pdf t^2 / cos_o, both
    // sides times cos_o^2: one division where there were two.
    const T a = st.bsdf_pdf * cos_o, pa = emitter_area_pdf<T>(s, Le) * (h.t * h.t);
    const T a2 = a * a;
    w = a2 > T(0) ? a2 / fmadd(pa, pa, a2) : T(0);
  }
  return st.beta * Vec3<T>(Le) * w;
}

template <uint32_t Kinds = kCompiledMaterialKinds, class T>
PB_HD PathEvent path_hit(const SceneView& s, const PathConfig& c, PathState<T>& st, const SurfaceHit<T>& h,
                         ShadowQuery<T>& shadow, bool& wants_shadow) {
  wants_shadow = false;
  const Material& m = s.material_of(h.prim);
  const T cos_o = -fdot(h.ng, st.ray.d);  // > 0: the ray hit the front side

  // 1. Emission (one-sided), weighted against light sampling when that could have
  //    found this point too.
  if (cos_o > T(0) && !is_zero(m.emission)) st.L += emitted_radiance<Kinds>(s, c, st, h, m.emission, cos_o);

  // 2. The bounce budget is spent, or the surface does not scatter.
  if (c.max_bounces >= 0 && st.depth >= uint32_t(c.max_bounces)) return PathEvent::Done;
  if (is_zero(m.albedo)) return PathEvent::Done;

  const Vec3<T> n = cos_o >= T(0) ? h.ng : -h.ng;  // two-sided: face the incoming ray
  const Frame<T> frame = Frame<T>::from_normal(n);
  const uint32_t vertex = st.depth + 1;
  const RngStream rng{st.pixel, c.seed};
  const Uniform4 ub = rng.draw(st.sample, vertex, kRngVertex);
  const Vec3<T> origin = offset_ray_origin(h.p, n, s.offset);

  // 3. Light sampling, where the BSDF is not a delta.
  if (c.sampling == Sampling::Nee && s.num_emitters > 0 && !bsdf_is_delta<Kinds>(m)) {
    float u_pick = ub.v[2];
    const uint32_t tri_id = s.emitters[pick_emitter(s, u_pick)];
    const Triangle tri = s.triangles[tri_id];
    const Vec3<T> v0 = Vec3<T>(s.positions[tri.v[0]]);
    const Vec3<T> e1 = Vec3<T>(s.positions[tri.v[1]]) - v0;
    const Vec3<T> e2 = Vec3<T>(s.positions[tri.v[2]]) - v0;
    const Barycentrics<T> b = sample_uniform_triangle(T(u_pick), T(ub.v[3]));
    const Vec3<T> y = fmadd(e2, b.b2, fmadd(e1, b.b1, v0));
    const Vec3<T> nl = fnormalize(fcross(e1, e2));
    Vec3<T> wi = y - h.p;
    const T dist2 = fdot(wi, wi);
    wi = wi * (T(1) / std::sqrt(dist2));
    const T cos_s = fdot(n, wi);
    const T cos_l = -fdot(nl, wi);
    if (cos_s > T(0) && cos_l > T(0) && dist2 > T(0)) {
      const Vec3f Le = s.material_of(tri_id).emission;
      const BsdfEval<T> f = bsdf_eval<Kinds>(m, frame, st.ray.d, wi, cos_s);
      // cos_s w / pdf_light, with w = power_heuristic(pdf_light, f.pdf) and pdf_light =
      // pa / cos_l (pa = area_pdf dist2): cos_s cos_l pa / (pa^2 + (f.pdf cos_l)^2), one
      // division where there were three.
      const T pa = emitter_area_pdf<T>(s, Le) * dist2;
      const T fc = f.pdf * cos_l;
      const T k = cos_s * cos_l * pa / fmadd(pa, pa, fc * fc);
      shadow.contribution = st.beta * f.f * Vec3<T>(Le) * k;
      const Vec3<T> target = offset_ray_origin(y, nl, s.offset);
      shadow.ray = {origin, target - origin};
      wants_shadow = true;
    }
  }

  // 4. Next direction from the BSDF.
  BsdfSample<T> bs;
  if (!bsdf_sample<Kinds>(m, c.sampling, frame, st.ray.d, cos_o >= T(0), ub, bs)) return PathEvent::Done;
  st.beta *= bs.weight;

  // 5. Russian roulette.
  if (c.russian_roulette && vertex >= c.rr_start_depth) {
    const T q = pmin(max_component(st.beta), T(0.95));
    if (!(T(rng.draw(st.sample, vertex, kRngRoulette).v[0]) < q)) return PathEvent::Done;
    st.beta = st.beta * (T(1) / q);
  }

  // A refracted ray leaves from the other side of the surface.
  Vec3<T> next_origin = origin;
  if constexpr (has_kind<Kinds>(MaterialKind::Dielectric))
    if (fdot(bs.wi, n) < T(0)) next_origin = offset_ray_origin(h.p, -n, s.offset);
  st.ray = {next_origin, bs.wi};
  st.bsdf_pdf = bs.pdf;
  st.depth = vertex;
  return PathEvent::Continue;
}

// ---- The last vertex of a bounded path --------------------------------------------
// Once the bounce budget is spent, the next hit can only add emitted light. A tracer
// may then skip the closest-hit query: path_final_query finds the closest emitter
// along the ray itself (watertight test against each emitter triangle) and asks for
// one occlusion test up to it. The path gains exactly what path_hit would add if that
// emitter were the closest hit, and for most rays (those that miss every emitter) no
// ray is traced at all. Used only where emitters are few enough to test one by one.
constexpr uint32_t kMaxEmittersForFinalQuery = 16;

template <class T>
PB_HD bool path_at_final_vertex(const SceneView& s, const PathConfig& c, const PathState<T>& st) {
  return c.max_bounces >= 0 && st.depth >= uint32_t(c.max_bounces) && s.num_emitters <= kMaxEmittersForFinalQuery;
}

// Returns true and fills `q` when an emitter facing the ray lies along it; the path is
// done either way.
template <uint32_t Kinds = kCompiledMaterialKinds, class T>
PB_HD bool path_final_query(const SceneView& s, const PathConfig& c, const PathState<T>& st, ShadowQuery<T>& q) {
  const WatertightRay wr = make_watertight_ray(Vec3f(st.ray.o), Vec3f(st.ray.d));
  float closest = 3.402823466e38f;
  uint32_t prim = ~0u;
  for (uint32_t k = 0; k < s.num_emitters; ++k) {
    const uint32_t id = s.emitters[k];
    const Triangle t = s.triangles[id];
    float th;
    if (intersect_watertight(wr, s.positions[t.v[0]], s.positions[t.v[1]], s.positions[t.v[2]], closest, th)) {
      closest = th;
      prim = id;
    }
  }
  if (prim == ~0u) return false;
  const SurfaceHit<T> h = surface_hit(s, prim, st.ray);
  const T cos_o = -fdot(h.ng, st.ray.d);
  const Vec3f Le = s.material_of(prim).emission;
  if (!(cos_o > T(0)) || is_zero(Le)) return false;
  q.contribution = emitted_radiance<Kinds>(s, c, st, h, Le, cos_o);
  q.ray = {st.ray.o, offset_ray_origin(h.p, h.ng, s.offset) - st.ray.o};  // up to just in front of it
  return true;
}

template <class T> PB_HD void shadow_unoccluded(PathState<T>& st, const ShadowQuery<T>& q) {
  st.L += q.contribution;
}

}  // namespace pb
