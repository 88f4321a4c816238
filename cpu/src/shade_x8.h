// The CPU's shading of kLanes paths at once (8 with AVX2, 16 with AVX-512): surface_hit + path_hit (path.h)
// for diffuse-only scenes in float, the case the paper's benchmark runs. Per lane it is
// path_hit's arithmetic in path_hit's order (simd8.h's operations are the lane-wise
// twins of the scalar ones), so each path gets bit for bit what the scalar path step
// gives it; the pixel-vs-wavefront tests (tests/unit/test_strategies.cpp) hold the two
// together. What cannot be done lane-wise -- loads by triangle or material id, the
// emitter choice, the random numbers, sin/cos -- runs per lane with the scalar code of
// the path step itself.
//
// Included once per instruction set, in a namespace named by PB_SIMD_NS with
// PB_SIMD_LANES lanes, under the matching `#pragma GCC target`, each in a translation
// unit of its own (shade_avx2.cpp, shade_avx512.cpp; g++ 12 fails on two copies in one):
// the lanes are one AVX or AVX-512 register. The strategies reach them through
// BatchKernels (batch_kernels.h), picked at run time by --isa. (Compiled for the SSE2
// baseline, every vector operation is two SSE ones, the lane shuffles are scalar code,
// and the batch costs more than the scalar path step.)
#include <cmath>
#include <cstdint>

#include "pathbench/common/path.h"
#include "shade_batch.h"
#include "simd8.h"


namespace pb::cpu::PB_SIMD_NS {

// Lane i of table t[0..n) at idx[i] (< n): from a register by one permutation where the
// table fits in one (paper-cornell's two emitters), else lane by lane (no branches).
template <class V, class E> struct LaneTable {
  LaneTable(const E* t, uint32_t n) : p(t), in_register(n <= uint32_t(kLanes)) {
    if (in_register) {
      E pad[kLanes] = {};
      std::memcpy(pad, t, n * sizeof(E));
      std::memcpy(&reg, pad, sizeof reg);
    }
  }
  V operator()(IV idx) const {
    if (in_register) {
#if PB_SIMD_LANES == 16
      return V(_mm512_permutexvar_ps(__m512i(idx), __m512(reg)));
#else
      return V(_mm256_permutevar8x32_ps(__m256(reg), __m256i(idx)));
#endif
    }
    V out;
    for (int i = 0; i < kLanes; ++i) out[i] = p[idx[i]];
    return out;
  }
  const E* p;
  bool in_register;
  V reg{};
};

// pick_emitter (path.h) for the lanes in `pick`, lane-wise: the same binary search over
// the emitters' CDF (each lane makes the comparisons the scalar search makes; lanes that
// are done wait), then the same rescaling of u. The picked lanes get the emitter's
// triangle in `light` and the rescaled u; the others keep theirs. (A scalar search per
// lane was a quarter of this kernel's time at 16 lanes: a mispredicted branch per lane.)
inline void pick_emitters(const SceneView& s, IV pick, FV& u, UV& light) {
  const LaneTable<FV, float> cdf(s.emitter_cdf, s.num_emitters);
  IV lo = IV{}, hi = splat_i(int32_t(s.num_emitters) - 1);
  for (IV active = lo < hi; lane_mask(active) != 0; active = lo < hi) {
    const IV mid = IV(UV(lo + hi) >> 1);  // (lo + hi) / 2, unsigned
    const IV left = u < cdf(mid);
    hi = select_i(active & left, mid, hi);
    lo = select_i(active & ~left, mid + 1, lo);
  }
  const FV below = select(lo > 0, cdf(select_i(lo > 0, lo - 1, IV{})), splat(0.0f));
  const FV width = cdf(lo) - below;
  const FV picked = select(width > 0.0f, vmin((u - below) / width, splat(0x1.fffffep-1f)), splat(0.0f));
  u = select(pick, picked, u);
  const LaneTable<UV, uint32_t> emitters(s.emitters, s.num_emitters);
  light = pick ? emitters(lo) : light;
}

// path_hit<kDiffuseOnly, float>(s, c, *st[i], surface_hit(s, prim[i], st[i]->ray), q, wants_shadow)
// for every lane i < b.lanes; `table` is built from `s`. What path_hit returns goes to
// the batch's streams (ShadeBatch): the shadow query's ray and contribution where
// wants_shadow, the next ray where the path goes on, packed per kind (Packer).
[[gnu::flatten]] inline void shade_diffuse(const SceneView& s, const PathConfig& c, const ShadeTable& table, ShadeBatch& b) {
  constexpr int N = kLanes;
  const bool nee = c.sampling == Sampling::Nee && s.num_emitters > 0;  // diffuse: never a delta BSDF
  // The paths' states, one lane each (PathState<float> is two 8-float rows).
  static_assert(sizeof(PathState<float>) == 16 * sizeof(float), "PathState<float>: 16 floats, as the rows below");
  const void* rows[N];
  for (int i = 0; i < N; ++i) rows[i] = b.st[i];
  FV ra[N], rb[N];
  load_rows(rows, 0, ra);
  load_rows(rows, 8, rb);
  const V3 o{ra[0], ra[1], ra[2]}, d{ra[3], ra[4], ra[5]};
  const V3 beta{ra[6], ra[7], rb[0]};
  V3 L{rb[1], rb[2], rb[3]};
  const FV bsdf_pdf = rb[4];
  const IV pixel = bits(rb[5]), sample = bits(rb[6]), depth = bits(rb[7]);
  const IV vertex = depth + 1;
  const IV mis_e = c.sampling == Sampling::Nee ? (depth > 0) : IV{};
  // The vertex's four uniforms, drawn for every lane (used only where the lane scatters).
  FV ub[4];
  rng_draw(UV(pixel), c.seed, UV(sample), UV(vertex), kRngVertex, ub);
  const FV u0 = ub[0], u1 = ub[1], u3 = ub[3];
  FV u_pick = ub[2];

  // The hit triangles: geometry and material (ShadeTable rows).
  const void* tri_rows[N];
  for (int i = 0; i < N; ++i) tri_rows[i] = table.row(b.prim[i]);
  FV ta[N], tb[N], tc[N];
  load_rows(tri_rows, 0, ta);
  load_rows(tri_rows, 8, tb);
  load_rows(tri_rows, 16, tc);
  const V3 v0{ta[0], ta[1], ta[2]}, e1{ta[3], ta[4], ta[5]}, e2{ta[6], ta[7], tb[0]};
  const V3 ng{tb[1], tb[2], tb[3]}, albedo{tb[4], tb[5], tb[6]};
  const IV emits = bits(tb[7]);
  const V3 Le{tc[0], tc[1], tc[2]};
  const IV at_budget = c.max_bounces >= 0 ? (depth >= c.max_bounces) : IV{};  // depth is small: signed compare is exact
  const IV scatters = bits(tc[3]) & ~at_budget;

  // The emitter light sampling picks (pick_emitters), then its rows.
  UV light;
  std::memcpy(&light, b.prim, sizeof light);  // any valid triangle where no emitter is chosen
  if (nee) pick_emitters(s, scatters, u_pick, light);
  for (int i = 0; i < N; ++i) tri_rows[i] = table.row(light[i]);
  FV la[N], lb[N], lc[N];
  load_rows(tri_rows, 0, la);
  load_rows(tri_rows, 8, lb);
  load_rows(tri_rows, 16, lc);
  const V3 l0{la[0], la[1], la[2]}, le1{la[3], la[4], la[5]}, le2{la[6], la[7], lb[0]};
  const V3 nl{lb[1], lb[2], lb[3]};
  const V3 le_light{lc[0], lc[1], lc[2]};

  // surface_hit (surface_hit.h).
  const V3 pv = fcross(d, e2);
  const FV inv_det = 1.0f / fdot(e1, pv);
  const V3 tv = o - v0;
  FV b1 = fdot(tv, pv) * inv_det;
  const V3 qv = fcross(tv, e1);
  FV b2 = fdot(d, qv) * inv_det;
  const FV t = fdot(e2, qv) * inv_det;
  b1 = vmin(vmax(b1, FV{}), splat(1.0f));
  b2 = vmin(vmax(b2, FV{}), 1.0f - b1);
  const V3 p = madd(e2, b2, madd(e1, b1, v0));

  // 1. Emission, MIS-weighted after the first vertex (emitted_radiance).
  const FV cos_o = -fdot(ng, d);
  const FV a_e = bsdf_pdf * cos_o, pa_e = mean3(Le) / s.emitter_power_total * (t * t);
  const FV a2_e = a_e * a_e;
  const FV mis_w = select(a2_e > 0.0f, a2_e / madd(pa_e, pa_e, a2_e), splat(0.0f));
  const FV w_e = select(mis_e, mis_w, splat(1.0f));
  L = select((cos_o > 0.0f) & emits, L + beta * Le * w_e, L);

  // 2.-5. For the lanes that scatter.
  const V3 n = select(cos_o >= 0.0f, ng, -ng);
  const FrameV frame = FrameV::from_normal(n);
  const V3 origin = offset_ray_origin(p, n, s.offset);

  // 3. Light sampling.
  IV shadow = IV{};
  V3 contribution{}, shadow_d{};
  if (nee) {
    const FV su = sqrt(u_pick);
    const FV tb1 = 1.0f - su, tb2 = u3 * su;
    const V3 y = madd(le2, tb2, madd(le1, tb1, l0));
    V3 wi = y - p;
    const FV dist2 = fdot(wi, wi);
    wi = wi * (1.0f / sqrt(dist2));
    const FV cos_s = fdot(n, wi);
    const FV cos_l = -fdot(nl, wi);
    shadow = scatters & (cos_s > 0.0f) & (cos_l > 0.0f) & (dist2 > 0.0f);
    const V3 f = albedo * splat(kInvPi<float>);
    const FV f_pdf = vmax(cos_s, FV{}) * kInvPi<float>;
    const FV pa = mean3(le_light) / s.emitter_power_total * dist2;
    const FV fc = f_pdf * cos_l;
    const FV k = cos_s * cos_l * pa / madd(pa, pa, fc * fc);
    contribution = beta * f * le_light * k;
    shadow_d = offset_ray_origin(y, nl, s.offset) - origin;
  }

  // 4. Next direction: lambert_sample (bsdf/lambert.h).
  FV r, z, pdf;
  V3 weight;
  if (c.sampling == Sampling::Uniform) {
    z = u0;
    r = sqrt(vmax(FV{}, madd(-z, z, 1.0f)));
    pdf = splat(uniform_hemisphere_pdf<float>());
    weight = albedo * (2.0f * z);
  } else {
    r = sqrt(u0);
    z = sqrt(vmax(FV{}, 1.0f - u0));
    pdf = vmax(z, FV{}) * kInvPi<float>;
    weight = albedo;
  }
  FV sin_phi, cos_phi;
  sincos_turns(u1, sin_phi, cos_phi);
  const V3 local{r * cos_phi, r * sin_phi, z};
  IV cont = scatters & (pdf > 0.0f) & (z > 0.0f);
  V3 beta_next = beta * weight;
  const V3 wi_next = frame.to_world(local);

  // 5. Russian roulette.
  if (c.russian_roulette) {
    const FV q = vmin(vmax(beta_next.x, vmax(beta_next.y, beta_next.z)), splat(0.95f));
    IV rr = IV{};
    for (int i = 0; i < N; ++i) {
      if (!cont[i] || uint32_t(vertex[i]) < c.rr_start_depth) continue;
      rr[i] = -1;
      const RngStream rng{uint32_t(pixel[i]), c.seed};
      if (!(rng.draw(uint32_t(sample[i]), uint32_t(vertex[i]), kRngRoulette).v[0] < q[i])) cont[i] = 0;
    }
    beta_next = select(rr, beta_next * (1.0f / q), beta_next);
  }

  // Back to the states: radiance always, the rest where the path goes on.
  ra[0] = select(cont, origin.x, ra[0]); ra[1] = select(cont, origin.y, ra[1]); ra[2] = select(cont, origin.z, ra[2]);
  ra[3] = select(cont, wi_next.x, ra[3]); ra[4] = select(cont, wi_next.y, ra[4]); ra[5] = select(cont, wi_next.z, ra[5]);
  ra[6] = select(cont, beta_next.x, ra[6]); ra[7] = select(cont, beta_next.y, ra[7]);
  rb[0] = select(cont, beta_next.z, rb[0]);
  rb[1] = L.x; rb[2] = L.y; rb[3] = L.z;
  rb[4] = select(cont, pdf, rb[4]);
  rb[7] = from_bits(cont ? vertex : depth);
  void* out_rows[N];
  for (int i = 0; i < N; ++i) out_rows[i] = b.st[i];
  store_rows(ra, out_rows, 0, b.lanes);
  store_rows(rb, out_rows, 8, b.lanes);

  // The lanes to the caller's streams (ShadeBatch), each kind packed in lane order.
  const uint32_t used = uint32_t((uint64_t(1) << b.lanes) - 1);
  const uint32_t m_cont = lane_mask(cont) & used, m_shadow = lane_mask(shadow) & used;
  const uint32_t m_final = m_cont & lane_mask(UV(vertex) >= (UV{} + b.final_depth));
  b.done = used & ~m_cont & ~m_shadow;
  UV tag;
  std::memcpy(&tag, b.tag, sizeof tag);
  if (ShadeStream* out = b.next) {
    const Packer pk(m_cont & ~m_final);
    const FV r[6] = {origin.x, origin.y, origin.z, wi_next.x, wi_next.y, wi_next.z};
    for (int j = 0; j < 6; ++j) pk.store(out->ray[j] + out->n, r[j]);
    pk.store(out->tag + out->n, tag);
    out->n += uint32_t(pk.count);
  }
  if (ShadeStream* out = b.final; out && m_final) {
    const Packer pk(m_final);
    pk.store(out->tag + out->n, tag);
    out->n += uint32_t(pk.count);
  }
  if (ShadeStream* out = b.shadow; out && m_shadow) {  // (m_shadow is 0 without nee)
    const Packer pk(m_shadow);
    const FV r[6] = {origin.x, origin.y, origin.z, shadow_d.x, shadow_d.y, shadow_d.z};
    for (int j = 0; j < 6; ++j) pk.store(out->ray[j] + out->n, r[j]);
    pk.store(out->contribution[0] + out->n, contribution.x);
    pk.store(out->contribution[1] + out->n, contribution.y);
    pk.store(out->contribution[2] + out->n, contribution.z);
    pk.store(out->tag + out->n, tag | UV(cont ? IV{} : splat_i(int32_t(ShadeStream::kEnds))));
    out->n += uint32_t(pk.count);
  }
}

}  // namespace pb::cpu::PB_SIMD_NS

namespace pb::cpu::PB_SIMD_NS {

// The last vertex of a bounded path (path_final_query, path.h), kLanes paths at once:
// whether any emitter lies along each lane's ray. The scalar query then runs only for
// the lanes marked here (false for most rays: the emitters are small), so this need
// only never say "no" where the scalar test would find a hit. It computes
// intersect_watertight's float arithmetic lane-wise with t_max = FLT_MAX for every
// emitter (the scalar loop's bound until its first hit), and marks any lane whose edge
// functions come out exactly 0 (where watertight.h falls back to double).
// Keep in step with common/include/pathbench/common/watertight.h.
inline void final_vertex_candidates(const SceneView& s, PathState<float>* const* st, bool* candidate) {
  constexpr int N = kLanes;
  const void* rows[N];
  for (int i = 0; i < N; ++i) rows[i] = st[i];
  FV ra[N];
  load_rows(rows, 0, ra);
  const V3 o{ra[0], ra[1], ra[2]}, d{ra[3], ra[4], ra[5]};
  // make_watertight_ray: the dominant axis kz, then kx, ky (swapped where d[kz] < 0).
  const FV ax = abs(d.x), ay = abs(d.y), az = abs(d.z);
  const IV z_is_x = (ax > ay) & (ax > az), z_is_y = ~z_is_x & (ay > az), z_is_z = ~z_is_x & ~z_is_y;
  const FV dz = select(z_is_x, d.x, select(z_is_y, d.y, d.z));
  // kx = kz + 1, ky = kz + 2 (mod 3); a negative dz swaps them.
  auto axis_after = [&](const V3& v, int step) {  // v[(kz + step) % 3]
    const FV next_of_x = step == 1 ? v.y : v.z, next_of_y = step == 1 ? v.z : v.x, next_of_z = step == 1 ? v.x : v.y;
    return select(z_is_x, next_of_x, select(z_is_y, next_of_y, next_of_z));
  };
  const IV swap = dz < 0.0f;
  auto axis_x = [&](const V3& v) { return select(swap, axis_after(v, 2), axis_after(v, 1)); };
  auto axis_y = [&](const V3& v) { return select(swap, axis_after(v, 1), axis_after(v, 2)); };
  auto axis_z = [&](const V3& v) { return select(z_is_x, v.x, select(z_is_y, v.y, v.z)); };
  (void)z_is_z;
  const FV sx = axis_x(d) / dz, sy = axis_y(d) / dz, sz = 1.0f / dz;
  const FV t_max = splat(3.402823466e38f);
  IV maybe = IV{};
  for (uint32_t k = 0; k < s.num_emitters; ++k) {
    const Triangle tri = s.triangles[s.emitters[k]];
    auto rel = [&](const Vec3f& p) { return V3{p.x - o.x, p.y - o.y, p.z - o.z}; };
    const V3 A = rel(s.positions[tri.v[0]]), B = rel(s.positions[tri.v[1]]), C = rel(s.positions[tri.v[2]]);
    const FV Az = axis_z(A), Bz = axis_z(B), Cz = axis_z(C);
    const FV Ax = axis_x(A) - sx * Az, Ay = axis_y(A) - sy * Az;
    const FV Bx = axis_x(B) - sx * Bz, By = axis_y(B) - sy * Bz;
    const FV Cx = axis_x(C) - sx * Cz, Cy = axis_y(C) - sy * Cz;
    const FV U = Cx * By - Cy * Bx, V = Ax * Cy - Ay * Cx, W = Bx * Ay - By * Ax;
    const IV on_edge = (U == 0.0f) | (V == 0.0f) | (W == 0.0f);
    const IV outside = ((U < 0.0f) | (V < 0.0f) | (W < 0.0f)) & ((U > 0.0f) | (V > 0.0f) | (W > 0.0f));
    const FV det = U + V + W;
    const FV T = U * (sz * Az) + V * (sz * Bz) + W * (sz * Cz);
    const IV in_range = (det > 0.0f) ? ((T > 0.0f) & (T < t_max * det)) : ((T < 0.0f) & (T > t_max * det));
    const FV t = T / det;
    const IV hit = ~outside & (det != 0.0f) & in_range & (t > 0.0f) & (t < t_max);
    maybe |= on_edge | hit;
  }
  for (int i = 0; i < N; ++i) candidate[i] = maybe[i] != 0;
}

}  // namespace pb::cpu::PB_SIMD_NS

namespace pb::cpu::PB_SIMD_NS {

// path_begin (path.h) for kLanes new paths: camera_ray (camera.h) lane-wise in its order
// of operations, the camera's random numbers from rng_draw.
inline void begin_paths(const SceneView& s, const PathConfig& c, const uint32_t* pixel, const uint32_t* sample,
                        PathState<float>* const* st, int lanes, float* const* rays) {
  constexpr int N = kLanes;
  UV pix, smp;
  IV px, py;
  for (int i = 0; i < N; ++i) {
    pix[i] = pixel[i];
    smp[i] = sample[i];
    px[i] = int32_t(pixel[i] % c.width);
    py[i] = int32_t(pixel[i] / c.width);
  }
  FV u[4];
  rng_draw(pix, c.seed, smp, UV{}, kRngCamera, u);
  const Camera& cam = s.camera;
  const float w = float(c.width), h = float(c.height);
  const float tan_y = cam.tan_half_fov_y;
  const float tan_x = tan_y * w / h;
  const float step = 2.0f * tan_y / h;
  const FV x = madd(__builtin_convertvector(px, FV) + u[0], step, -tan_x);
  const FV y = madd(-(__builtin_convertvector(py, FV) + u[1]), step, tan_y);
  auto bc = [](const Vec3f& v) { return V3{splat(v.x), splat(v.y), splat(v.z)}; };
  const V3 d = fnormalize(madd(bc(cam.up), y, madd(bc(cam.right), x, bc(cam.forward))));
  FV ra[N], rb[N];
  ra[0] = splat(cam.position.x); ra[1] = splat(cam.position.y); ra[2] = splat(cam.position.z);
  ra[3] = d.x; ra[4] = d.y; ra[5] = d.z;
  ra[6] = ra[7] = rb[0] = splat(1.0f);             // beta
  rb[1] = rb[2] = rb[3] = rb[4] = FV{};            // L, bsdf_pdf
  rb[5] = from_bits(IV(pix)); rb[6] = from_bits(IV(smp)); rb[7] = FV{};  // pixel, sample, depth 0
  void* out_rows[N];
  for (int i = 0; i < N; ++i) out_rows[i] = st[i];
  store_rows(ra, out_rows, 0, lanes);
  store_rows(rb, out_rows, 8, lanes);
  if (rays)
    for (int j = 0; j < 6; ++j) store_first(rays[j], ra[j], lanes);
}

}  // namespace pb::cpu::PB_SIMD_NS
