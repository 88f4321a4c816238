// The CPU wavefront's shading of eight paths at once: surface_hit + path_hit (path.h)
// for diffuse-only scenes in float, the case the paper's benchmark runs. Per lane it is
// path_hit's arithmetic in path_hit's order (simd8.h's operations are the lane-wise
// twins of the scalar ones), so each path gets bit for bit what the scalar path step
// gives it; the pixel-vs-wavefront tests (tests/unit/test_strategies.cpp) hold the two
// together. What cannot be done lane-wise -- loads by triangle or material id, the
// emitter choice, the random numbers, sin/cos -- runs per lane with the scalar code of
// the path step itself.
//
// Included in a namespace named by PB_SIMD_NS under `#pragma GCC target("avx2")`
// (render_wavefront.cpp): eight lanes are one AVX register. (Compiled for the SSE2
// baseline, every vector operation is two SSE ones, the lane shuffles are scalar code,
// and the batch costs more than the scalar path step; g++ 12 also fails on an SSE2 and
// an AVX2 copy in one translation unit.)
#include <cmath>
#include <cstdint>

#include "pathbench/common/path.h"
#include "simd8.h"

#ifndef PB_CPU_SHADE8_DEFINED
#define PB_CPU_SHADE8_DEFINED
namespace pb::cpu {
constexpr int kShadeLanes = 8;
// One batch: eight paths that hit a triangle, and what shading them asks for next.
struct Shade8 {
  PathState<float>* st[kShadeLanes];
  ShadowQuery<float>* shadow[kShadeLanes];
  uint32_t prim[kShadeLanes];  // hit triangle of each lane
  int lanes;                   // lanes in use; the rest repeat lane 0 and write nothing
  bool wants_shadow[kShadeLanes];
  bool cont[kShadeLanes];      // PathEvent::Continue
};
}  // namespace pb::cpu::PB_SIMD_NS
#endif

namespace pb::cpu::PB_SIMD_NS {

// path_hit<kDiffuseOnly, float>(s, c, *st[i], surface_hit(s, prim[i], st[i]->ray), *shadow[i], wants_shadow[i])
// for every lane i.
[[gnu::noinline, gnu::flatten]] inline void shade_diffuse_x8(const SceneView& s, const PathConfig& c, Shade8& b) {
  constexpr int N = kLanes;
  const bool nee = c.sampling == Sampling::Nee && s.num_emitters > 0;  // diffuse: never a delta BSDF
  V3 v0, v1, v2, albedo, Le;
  V3 l0, l1, l2, le_light;  // the chosen emitter triangle and its emission
  I8 emits, scatters;

  // The paths' states, one lane each (PathState<float> is two 8-float rows).
  static_assert(sizeof(PathState<float>) == 2 * sizeof(F8), "PathState<float>: 16 floats, as the rows below");
  const void* rows[N];
  for (int i = 0; i < N; ++i) rows[i] = b.st[i];
  F8 ra[N], rb[N];
  load_rows(rows, 0, ra);
  load_rows(rows, 8, rb);
  const V3 o{ra[0], ra[1], ra[2]}, d{ra[3], ra[4], ra[5]};
  const V3 beta{ra[6], ra[7], rb[0]};
  V3 L{rb[1], rb[2], rb[3]};
  const F8 bsdf_pdf = rb[4];
  const I8 pixel = bits(rb[5]), sample = bits(rb[6]), depth = bits(rb[7]);
  const I8 vertex = depth + 1;
  const I8 mis_e = c.sampling == Sampling::Nee ? (depth > 0) : I8{};
  // The vertex's four uniforms, drawn for every lane (used only where the lane scatters).
  F8 ub[4];
  rng_draw(U8(pixel), c.seed, U8(sample), U8(vertex), kRngVertex, ub);
  const F8 u0 = ub[0], u1 = ub[1], u3 = ub[3];
  F8 u_pick = ub[2];

  // Per lane: the hit triangle and its material, which lanes scatter, their random
  // numbers and emitter choice.
  for (int i = 0; i < N; ++i) {
    const Triangle tri = s.triangles[b.prim[i]];
    const Vec3f a = s.positions[tri.v[0]], bb = s.positions[tri.v[1]], cc = s.positions[tri.v[2]];
    v0.x[i] = a.x; v0.y[i] = a.y; v0.z[i] = a.z;
    v1.x[i] = bb.x; v1.y[i] = bb.y; v1.z[i] = bb.z;
    v2.x[i] = cc.x; v2.y[i] = cc.y; v2.z[i] = cc.z;
    const Material& m = s.material_of(b.prim[i]);
    Le.x[i] = m.emission.x; Le.y[i] = m.emission.y; Le.z[i] = m.emission.z;
    albedo.x[i] = m.albedo.x; albedo.y[i] = m.albedo.y; albedo.z[i] = m.albedo.z;
    emits[i] = is_zero(m.emission) ? 0 : -1;
    const bool at_budget = c.max_bounces >= 0 && uint32_t(depth[i]) >= uint32_t(c.max_bounces);
    scatters[i] = (!at_budget && !is_zero(m.albedo)) ? -1 : 0;
    uint32_t light = b.prim[i];  // any valid triangle where no emitter is chosen
    if (nee && scatters[i]) {
      float up = u_pick[i];
      light = s.emitters[pick_emitter(s, up)];
      u_pick[i] = up;
    }
    const Triangle lt = s.triangles[light];
    const Vec3f la = s.positions[lt.v[0]], lb = s.positions[lt.v[1]], lc = s.positions[lt.v[2]];
    l0.x[i] = la.x; l0.y[i] = la.y; l0.z[i] = la.z;
    l1.x[i] = lb.x; l1.y[i] = lb.y; l1.z[i] = lb.z;
    l2.x[i] = lc.x; l2.y[i] = lc.y; l2.z[i] = lc.z;
    const Vec3f lle = s.material_of(light).emission;
    le_light.x[i] = lle.x; le_light.y[i] = lle.y; le_light.z[i] = lle.z;
  }

  // surface_hit (surface_hit.h).
  const V3 e1 = v1 - v0, e2 = v2 - v0;
  const V3 pv = cross(d, e2);
  const F8 inv_det = 1.0f / dot(e1, pv);
  const V3 tv = o - v0;
  F8 b1 = dot(tv, pv) * inv_det;
  const V3 qv = cross(tv, e1);
  F8 b2 = dot(d, qv) * inv_det;
  const F8 t = dot(e2, qv) * inv_det;
  b1 = vmin(vmax(b1, F8{}), splat(1.0f));
  b2 = vmin(vmax(b2, F8{}), 1.0f - b1);
  const V3 p = v0 + e1 * b1 + e2 * b2;
  const V3 ng = normalize(cross(e1, e2));

  // 1. Emission, MIS-weighted after the first vertex (emitted_radiance).
  const F8 cos_o = -dot(ng, d);
  const F8 pdf_e = mean3(Le) / s.emitter_power_total * t * t / cos_o;
  const F8 w_e = select(mis_e, power_heuristic(bsdf_pdf, pdf_e), splat(1.0f));
  L = select((cos_o > 0.0f) & emits, L + beta * Le * w_e, L);

  // 2.-5. For the lanes that scatter.
  const V3 n = select(cos_o >= 0.0f, ng, -ng);
  const Frame8 frame = Frame8::from_normal(n);
  const V3 origin = offset_ray_origin(p, n, s.offset);

  // 3. Light sampling.
  I8 shadow = I8{};
  V3 contribution, shadow_d;
  if (nee) {
    const V3 le1 = l1 - l0, le2 = l2 - l0;
    const F8 su = sqrt(u_pick);
    const F8 tb1 = 1.0f - su, tb2 = u3 * su;
    const V3 y = l0 + le1 * tb1 + le2 * tb2;
    const V3 nl = normalize(cross(le1, le2));
    V3 wi = y - p;
    const F8 dist2 = dot(wi, wi);
    wi = wi / sqrt(dist2);
    const F8 cos_s = dot(n, wi);
    const F8 cos_l = -dot(nl, wi);
    shadow = scatters & (cos_s > 0.0f) & (cos_l > 0.0f) & (dist2 > 0.0f);
    const F8 pdf_light = mean3(le_light) / s.emitter_power_total * dist2 / cos_l;
    const V3 f = albedo * splat(kInvPi<float>);
    const F8 f_pdf = vmax(cos_s, F8{}) * kInvPi<float>;
    const F8 w = power_heuristic(pdf_light, f_pdf);
    contribution = beta * f * le_light * (cos_s * w / pdf_light);
    shadow_d = offset_ray_origin(y, nl, s.offset) - origin;
  }

  // 4. Next direction: lambert_sample (bsdf/lambert.h).
  F8 r, z, pdf;
  if (c.sampling == Sampling::Uniform) {
    z = u0;
    r = sqrt(vmax(F8{}, 1.0f - z * z));
    pdf = splat(uniform_hemisphere_pdf<float>());
  } else {
    r = sqrt(u0);
    z = sqrt(vmax(F8{}, 1.0f - u0));
    pdf = vmax(z, F8{}) * kInvPi<float>;
  }
  const F8 phi = 2.0f * kPi<float> * u1;
  F8 cos_phi, sin_phi;
  for (int i = 0; i < N; ++i) {
    cos_phi[i] = std::cos(phi[i]);
    sin_phi[i] = std::sin(phi[i]);
  }
  const V3 local{r * cos_phi, r * sin_phi, z};
  I8 cont = scatters & (pdf > 0.0f) & (z > 0.0f);
  V3 beta_next = beta * (albedo * splat(kInvPi<float>) * (z / pdf));
  const V3 wi_next = frame.to_world(local);

  // 5. Russian roulette.
  if (c.russian_roulette) {
    const F8 q = vmin(vmax(beta_next.x, vmax(beta_next.y, beta_next.z)), splat(0.95f));
    I8 rr = I8{};
    for (int i = 0; i < N; ++i) {
      if (!cont[i] || uint32_t(vertex[i]) < c.rr_start_depth) continue;
      rr[i] = -1;
      const RngStream rng{uint32_t(pixel[i]), c.seed};
      if (!(rng.draw(uint32_t(sample[i]), uint32_t(vertex[i]), kRngRoulette).v[0] < q[i])) cont[i] = 0;
    }
    beta_next = select(rr, beta_next / q, beta_next);
  }

  // Back to the states: radiance always, the rest where the path goes on.
  ra[0] = select(cont, origin.x, ra[0]); ra[1] = select(cont, origin.y, ra[1]); ra[2] = select(cont, origin.z, ra[2]);
  ra[3] = select(cont, wi_next.x, ra[3]); ra[4] = select(cont, wi_next.y, ra[4]); ra[5] = select(cont, wi_next.z, ra[5]);
  ra[6] = select(cont, beta_next.x, ra[6]); ra[7] = select(cont, beta_next.y, ra[7]);
  rb[0] = select(cont, beta_next.z, rb[0]);
  rb[1] = L.x; rb[2] = L.y; rb[3] = L.z;
  rb[4] = select(cont, pdf, rb[4]);
  rb[7] = from_bits(cont ? vertex : depth);
  transpose8(ra);
  transpose8(rb);
  for (int i = 0; i < b.lanes; ++i) {
    std::memcpy(reinterpret_cast<float*>(b.st[i]), &ra[i], sizeof(F8));
    std::memcpy(reinterpret_cast<float*>(b.st[i]) + 8, &rb[i], sizeof(F8));
    b.wants_shadow[i] = shadow[i] != 0;
    b.cont[i] = cont[i] != 0;
    if (shadow[i]) {
      ShadowQuery<float>& q = *b.shadow[i];
      q.ray = {{origin.x[i], origin.y[i], origin.z[i]}, {shadow_d.x[i], shadow_d.y[i], shadow_d.z[i]}};
      q.contribution = {contribution.x[i], contribution.y[i], contribution.z[i]};
    }
  }
}

}  // namespace pb::cpu::PB_SIMD_NS
