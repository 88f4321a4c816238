// (No include guard: included once per instruction set by shade_kernels.inc, after
// simd8.h, under a target that adds FMA.) The tiny-scene test (tiny_scene.h): kLanes rays
// against every triangle of a TinyScene, lanes = rays.
//
// Per triangle it evaluates Embree 3's robust Pluecker test operation for operation
// (vertices relative to the ray origin, edges, edge functions U, V, W as
// dot(cross(e, v + v'), D) with FMA as Embree's madd / msub, the normal by
// stable_triangle_normal, den and T doubled), then decides with margins instead of
// Embree's exact comparisons:
//   inside  all of U, V, W beyond +-m with one sign     outside  some beyond +m, some beyond -m
//   front   t > tnear (1 + 2^-20) + slack                behind   t < tnear (1 - 2^-20) - slack
//   before  t < tfar (1 - 2^-20) - slack                 beyond   t > tfar (1 + 2^-20) + slack
//   grazing |den| within 32x its rounding slack (its sign and size in doubt)
// A candidate inside, front, before and not grazing is a proven hit: Embree's test accepts
// it too. One outside, or (not grazing) behind or beyond, is proven irrelevant. Anything
// else (near an edge, near the origin's own surface, near tfar) is a doubt at distance
// t - err (0 when its depth is in doubt). A ray is unsure when a doubt or a second proven
// hit reaches into its nearest proven hit's error interval (or it has doubts and no proven
// hit): Embree decides those (tiny_scene.h). Both computations start from the same
// rounded values (v = p - o, e = v - v', v + v' are single IEEE operations in either) and
// continue with the same operations, so the margins are slack for rounding-order
// differences: m = 2^-16 E M |D|_1 (E: this triangle's largest edge component, M: a bound
// on |vertex - origin| over the scene), T's band 2^-20 |v0|_inf (|Ng|_1 + 3 E^2), den's
// 2^-20 |Ng|_1 |D|_1, t's error (band + t den band) / |den| + 2^-20 t (Embree's rcp).
// tnear is the rays' (embree_rays.h: watertight.h's ray_t_min, a few ulps of the origin),
// compared in T as tfar is. docs/notes/cpu-log.md gives the argument.
namespace pb::cpu::PB_SIMD_NS {

#if PB_SIMD_LANES == 16
inline FV fmsub(FV a, FV b, FV c) { return FV(_mm512_fmsub_ps(__m512(a), __m512(b), __m512(c))); }
#else
inline FV fmsub(FV a, FV b, FV c) { return FV(_mm256_fmsub_ps(__m256(a), __m256(b), __m256(c))); }
#endif

// Embree's Vec3 dot and cross (common/math/vec3.h), madd / msub as single FMAs, are the
// path step's fused fdot and fcross (simd8.h): the same operations, so the same bits
// (fcross's a*b + -(c*d) rounds as msub's a*b - c*d).
// Embree's stable_triangle_normal(a, b, c) (common/math/vec3.h): per component, the
// cross product of the pair whose subtracted product is smaller.
inline V3 emb_stable_normal(V3 a, V3 b, V3 c) {
  const FV ab_x = a.z * b.y, ab_y = a.x * b.z, ab_z = a.y * b.x;
  const FV bc_x = b.z * c.y, bc_y = b.x * c.z, bc_z = b.y * c.x;
  const V3 cab{fmsub(a.y, b.z, ab_x), fmsub(a.z, b.x, ab_y), fmsub(a.x, b.y, ab_z)};
  const V3 cbc{fmsub(b.y, c.z, bc_x), fmsub(b.z, c.x, bc_y), fmsub(b.x, c.y, bc_z)};
  return {select(abs(ab_x) < abs(bc_x), cab.x, cbc.x), select(abs(ab_y) < abs(bc_y), cab.y, cbc.y),
          select(abs(ab_z) < abs(bc_z), cab.z, cbc.z)};
}

// The plane cull: a segment [0, t_end] whose both ends lie on one side of the triangle's
// plane by more than the margin never reaches it, in Embree's arithmetic too (the margin,
// 2^-15 of `scale` and more for slivers, is >= 16x the float error of this test plus
// Embree's T, den and its normal's rounding: docs/notes/cpu-log.md). Far cheaper than the depth or
// the edges for the walls of a closed box, which every shadow segment, and every segment
// up to a found hit, misses.
inline IV plane_away(const TinyScene::Triangle& tr, V3 o, V3 d, FV t_end, FV scale) {
  const V3 n{splat(tr.n[0]), splat(tr.n[1]), splat(tr.n[2])};
  const FV s0 = madd_v(n.x, o.x, madd_v(n.y, o.y, fmsub(n.z, o.z, splat(tr.c))));
  const FV s1 = madd_v(t_end, fdot(n, d), s0);
  const FV mu = scale * tr.cull_k;
  return ((s0 > mu) & (s1 > mu)) | ((s0 < -mu) & (s1 < -mu));
}

struct TinyResult {
  FV best, best_err;  // nearest proven hit's distance and its error (0 while there is none)
  FV other_lo;       // lowest bottom of any other proven hit's or doubt's interval
  UV id;             // scene triangle of `best`
};

// The axis-plane test's per-ray data (tiny_scene.h AxisGroup; docs/notes/cpu-log.md gives
// the argument). Per axis c: 1 / D_c; the edge margin's factors (m = G a_c + b_c, G =
// |X - R|_inf in the plane); whether a lane may use the test for a plane of normal axis c
// (`ok`: its origin and D_c in the ranges the argument needs, M <= the scene's
// axis_m_ok); D_c == 0 (Embree's den is 0: it rejects every such triangle).
struct AxisRays {
  FV inv_d[3], ma[3], mb[3];
  IV ok[3], d_zero[3];
  FV tn_front, tn_behind, tf_before, tf_beyond;  // tnear and tfar, widened by Embree's and our t error
};

inline IV in_range(FV a, float lo, float hi) { return (a >= lo) & (a <= hi); }

inline void axis_rays(const TinyScene& s, const FV* oc, const FV* dc, FV omax, FV tnear, FV tfar, AxisRays& a) {
  IV base = omax <= s.axis_o_ok;  // M <= |o|_inf + pmax <= axis_m_ok
  for (int c = 0; c < 3; ++c) base &= (oc[c] == 0.0f) | in_range(abs(oc[c]), 0x1p-20f, 0x1p20f);
  for (int c = 0; c < 3; ++c) {
    a.inv_d[c] = 1.0f / dc[c];
    a.ok[c] = base & in_range(abs(dc[c]), 0x1p-20f, 0x1p20f);
    a.d_zero[c] = base & (dc[c] == 0.0f);
  }
  // |Embree's t - our t| <= 11 u |t| (the entry); the bands are 2^-18 (5.8x that).
  a.tn_front = tnear * (1.0f + 0x1p-18f);
  a.tn_behind = tnear * (1.0f - 0x1p-18f);
  a.tf_before = tfar * (1.0f - 0x1p-18f);
  a.tf_beyond = tfar * (1.0f + 0x1p-18f);
}
// The edge margins' factors, computed where a first edge test is needed (shadow rays
// seldom need one).
inline void axis_margins(const TinyScene& s, FV m_bound, FV d1, AxisRays& a) {
  // Embree's error against exact arithmetic (vertex rounding and its formula), plus its
  // tolerance and our error, in units of our edge functions: u K (6 M G + 17 E G + 32 E M
  // + 22 E^2), K = |D|_1 / |D_c|, u = 2^-24 (the entry's derivation); times 3.
  const float E = s.axis_e;
  const FV a_c = 0x1p-24f * madd(18.0f, m_bound, splat(51.0f * E));
  const FV b_c = (0x1p-24f * E) * madd(96.0f, m_bound, splat(66.0f * E));
  for (int c = 0; c < 3; ++c) {
    const FV K = d1 * abs(a.inv_d[c]);
    a.ma[c] = K * a_c;
    a.mb[c] = K * b_c;
  }
}

// The closest-hit bookkeeping of one candidate (a triangle, or a group's two halves at
// one t): `proven` a hit at t (Embree's t within err), `doubt` neither proven nor
// irrelevant (at t - err where `known`, else anywhere from 0).
template <bool AnyHit>
inline void tiny_update(TinyResult& r, IV proven, IV doubt, FV t, FV err, IV known, UV id) {
  if constexpr (AnyHit) {
    r.best = select(proven, t, r.best);
    r.other_lo = select(doubt, splat(0.0f), r.other_lo);
    return;
  }
  const FV doubt_lo = select(known, t - err, splat(0.0f));
  const IV nearer = proven & (t < r.best);
  r.other_lo = select(proven, vmin(r.other_lo, select(nearer, r.best - r.best_err, t - err)), r.other_lo);
  r.other_lo = select(doubt, vmin(r.other_lo, doubt_lo), r.other_lo);
  r.best = select(nearer, t, r.best);
  r.best_err = select(nearer, err, r.best_err);
  r.id = nearer ? id : r.id;
}

// The general triangles (tiny_scene.h `general`): Embree's robust Pluecker test operation
// for operation, with margins (the header comment above).
template <bool AnyHit>
inline void general_test(const TinyScene& s, V3 o, V3 d, FV tfar, FV m_bound, FV d1, FV omax, FV dmx, FV tnear,
                         TinyResult& r) {
  const FV m_scale = 0x1p-16f * m_bound * d1;  // times this triangle's E
  const FV inf = splat(__builtin_inff());
  const FV tfar_lo = tfar * (1.0f - 0x1p-20f), tfar_hi = tfar * (1.0f + 0x1p-20f);
  const FV tfar_finite = select(tfar < splat(__builtin_inff()), tfar, splat(0.0f));
  const FV tnear_lo = tnear * (1.0f - 0x1p-20f), tnear_hi = tnear * (1.0f + 0x1p-20f);
  // The plane cull's scale (below): |o|_inf + t_end |d|_inf + the scene's largest
  // coordinate bounds |x| on the segment and |vertex - x|. Shadow rays: t_end = tfar
  // (inf: never culled). Closest hits: once every lane has a proven hit, t_end = its far
  // end, best + err: a triangle the segment misses is farther than the hit in Embree's
  // arithmetic too, and clear of its interval.
  const FV dmax = dmx;
  const FV cull_base = omax + s.pmax;
  const FV shadow_scale = madd_v(tfar, dmax, cull_base);
  for (const uint32_t row : s.general) {
    const TinyScene::Triangle& tr = s.triangles[row];
    if constexpr (AnyHit) {
      // Skipped where every lane is away or blocked already.
      if (lane_mask(~plane_away(tr, o, d, tfar, shadow_scale) & (r.best == inf)) == 0) continue;
    } else if (lane_mask(r.best == inf) == 0) {
      const FV t_end = r.best + r.best_err;
      if (lane_mask(~plane_away(tr, o, d, t_end, madd_v(t_end, dmax, cull_base))) == 0) continue;
    }
    const V3 v0 = V3{splat(tr.p[0]), splat(tr.p[1]), splat(tr.p[2])} - o;
    const V3 v1 = V3{splat(tr.p[3]), splat(tr.p[4]), splat(tr.p[5])} - o;
    const V3 v2 = V3{splat(tr.p[6]), splat(tr.p[7]), splat(tr.p[8])} - o;
    const V3 e0 = v2 - v0, e1 = v0 - v1, e2 = v1 - v2;
    // The edge functions and the depth, in the order that lets the most triangles go
    // early: for shadow rays the depth first (every wall of a closed box is crossed
    // behind the origin or beyond tfar), for closest hits the edges first.
    struct Edges {
      IV outside, inside_any;  // inside_any: inside, before the grazing test
    };
    auto edges = [&] {
      const FV U = fdot(fcross(e0, v2 + v0), d);
      const FV V = fdot(fcross(e1, v0 + v1), d);
      const FV W = fdot(fcross(e2, v1 + v2), d);
      const FV lo = vmin(vmin(U, V), W), hi = vmax(vmax(U, V), W);
      const FV m = m_scale * tr.edge;
      return Edges{(hi > m) & (lo < -m), (lo > m) | (hi < -m)};
    };
    struct Depth {
      FV abs_den, Ts, band, den_band;
      IV grazing, front, before, away;
    };
    auto depth = [&] {
      const V3 ng = emb_stable_normal(e0, e1, e2);
      FV den = fdot(ng, d);
      den = den + den;
      FV T = fdot(v0, ng);
      T = T + T;
      Depth z;
      z.abs_den = abs(den);
      z.Ts = from_bits(bits(T) ^ (bits(den) & int32_t(0x80000000u)));  // T with den's sign: t = Ts / |den|
      // Same inputs, same operations as Embree 3.13's source: the same T and den. The
      // bands are slack for rounding-order differences all the same: in the dots
      // (relative to |v0| |Ng| for T, |Ng| |D| for den) and, for T, a normal that picked
      // the other cross product (relative to E^2).
      const FV ng1 = abs(ng.x) + abs(ng.y) + abs(ng.z);
      const FV v0max = vmax(vmax(abs(v0.x), abs(v0.y)), abs(v0.z));
      z.band = 0x1p-20f * v0max * (ng1 + 3.0f * tr.edge * tr.edge);
      z.den_band = 0x1p-20f * ng1 * d1;
      z.grazing = z.abs_den <= 32.0f * z.den_band;  // den's sign and size in doubt
      const FV tnear_slack = z.band + z.den_band * tnear;
      z.front = z.Ts > z.abs_den * tnear_hi + tnear_slack;
      const IV behind = z.Ts < z.abs_den * tnear_lo - tnear_slack;
      const FV tfar_slack = z.band + z.den_band * tfar_finite;
      z.before = z.Ts < z.abs_den * tfar_lo - tfar_slack;
      const IV beyond = z.Ts > z.abs_den * tfar_hi + tfar_slack;
      // den == 0: Embree rejects the triangle outright (a ray in its plane).
      z.away = (z.abs_den == 0.0f) | (~z.grazing & (behind | beyond));
      return z;
    };
    Edges ed;
    Depth z;
    if constexpr (AnyHit) {
      z = depth();
      if (lane_mask(~z.away) == 0) continue;
      ed = edges();
    } else {
      ed = edges();
      if (lane_mask(~ed.outside) == 0) continue;
      z = depth();
    }
    const IV proven = ed.inside_any & ~z.grazing & z.front & z.before;
    const IV doubt = ~proven & ~ed.outside & ~z.away;
    const FV rcp = 1.0f / z.abs_den;
    const FV t = z.Ts * rcp;
    const FV err = (z.band + abs(t) * z.den_band) * rcp + 0x1p-20f * abs(t);
    tiny_update<AnyHit>(r, proven, doubt, t, err, z.front & ~z.grazing, UV{} + tr.triangle);
    if constexpr (AnyHit) {
      if (lane_mask(r.best == inf) == 0) return;  // every ray blocked: doubts no longer matter
    }
  }
}

// Every triangle of `s` against the rays; `AnyHit` (occlusion): only whether a proven
// hit exists, and stop once every lane has one.
template <bool AnyHit>
inline TinyResult tiny_test(const TinyScene& s, const float* const* rays, const float* tfar_in) {
  FV c[6], tfar;
  for (int j = 0; j < 6; ++j) c[j] = load_lanes(rays[j]);
  tfar = load_lanes(tfar_in);
  const V3 o{c[0], c[1], c[2]}, d{c[3], c[4], c[5]};
  const FV oc[3] = {o.x, o.y, o.z}, dc[3] = {d.x, d.y, d.z};
  // M: a bound on |vertex - origin| (every component, every vertex), with its rounding;
  // only where the margins need it.
  auto m_bound_of = [&] {
    FV m = splat(0.0f);
    for (int j = 0; j < 3; ++j) m = vmax(m, vmax(abs(s.hi[j] - oc[j]), abs(oc[j] - s.lo[j])));
    return m * (1.0f + 0x1p-20f);
  };
  const FV d1 = abs(d.x) + abs(d.y) + abs(d.z);
  const FV inf = splat(__builtin_inff());
  // Embree's tnear for these rays (embree_rays.h: ray_t_min, watertight.h), in the same
  // float operations.
  const FV omax = vmax(vmax(abs(o.x), abs(o.y)), abs(o.z)), dmx = vmax(vmax(abs(d.x), abs(d.y)), abs(d.z));
  const FV tnear = select(dmx > 0.0f, 0x1p-21f * omax * (1.0f / dmx), splat(0.0f));
  TinyResult r{inf, splat(0.0f), inf, UV{} + RTC_INVALID_GEOMETRY_ID};
  if (!s.groups.empty()) {
    AxisRays a;
    axis_rays(s, oc, dc, omax, tnear, tfar, a);
    bool margins = false;
    for (const TinyScene::AxisGroup& g : s.groups) {
      const int k = g.k;
      const FV t = (bcast(g.P) - oc[k]) * a.inv_d[k];  // P - o_k: Embree's own first operation
      const IV ok = a.ok[k];
      const IV front = t > a.tn_front, before = t < a.tf_before;
      IV away = a.d_zero[k] | (ok & ((t < a.tn_behind) | (t > a.tf_beyond)));
      IV done;
      if constexpr (AnyHit) {
        done = away | (r.best < inf);  // blocked lanes need no answer
      } else {
        // Beyond the lane's proven hit and its interval: it can neither win nor make the
        // lane unsure (as the plane cull below).
        away |= ok & (t * (1.0f - 0x1p-18f) > r.best + r.best_err);
        done = away;
      }
      if (lane_mask(~done) == 0) continue;
      if (!margins) {
        axis_margins(s, m_bound_of(), d1, a);
        margins = true;
      }
      const int i = g.i, j = g.j;
      const FV yi = madd_v(t, dc[i], oc[i] - bcast(g.Ri)), yj = madd_v(t, dc[j], oc[j] - bcast(g.Rj));
      const FV m = madd_v(vmax(abs(yi), abs(yj)), a.ma[k], a.mb[k]);
      const IV hit_ok = ok & front & before & ~away;
      // Triangle h of the group: proven hit, or away (rejected by Embree or beyond).
      auto half = [&](int h, IV& proven, IV& away_h) {
        const float(*e)[3] = g.e[h];
        const FV f0 = madd_v(bcast(e[0][0]), yi, madd_v(bcast(e[0][1]), yj, bcast(e[0][2])));
        const FV f1 = madd_v(bcast(e[1][0]), yi, madd_v(bcast(e[1][1]), yj, bcast(e[1][2])));
        const FV f2 = madd_v(bcast(e[2][0]), yi, madd_v(bcast(e[2][1]), yj, bcast(e[2][2])));
        const FV lo = vmin(vmin(f0, f1), f2), hi = vmax(vmax(f0, f1), f2);
        proven = hit_ok & (lo > m);
        away_h = away | (ok & (lo < -m) & (hi > m));
      };
      IV p0, a0;
      half(0, p0, a0);
      const FV err = abs(t) * 0x1p-19f;  // 2.9x the bound
      const IV known = ok & front;
      if (g.count == 1) {
        tiny_update<AnyHit>(r, p0, ~p0 & ~a0, t, err, known, UV{} + g.id[0]);
      } else {
        IV p1, a1;
        half(1, p1, a1);
        if constexpr (AnyHit) {
          tiny_update<AnyHit>(r, p0 | p1, (~p0 & ~a0) | (~p1 & ~a1), t, err, known, UV{});
        } else {
          // One candidate at t: a proven hit where one half is and the other is away; a
          // doubt where neither is away and not exactly one proven.
          const IV proven = (p0 & a1) | (p1 & a0);
          tiny_update<AnyHit>(r, proven, ~proven & ~(a0 & a1), t, err, known, p0 ? UV{} + g.id[0] : UV{} + g.id[1]);
        }
      }
      if constexpr (AnyHit) {
        if (lane_mask(r.best == inf) == 0) return r;  // every ray blocked: doubts no longer matter
      }
    }
  }
  if (!s.general.empty()) general_test<AnyHit>(s, o, d, tfar, m_bound_of(), d1, omax, dmx, tnear, r);
  return r;
}

inline uint32_t tiny_closest(const TinyScene& s, const float* const* rays, const float* tfar, uint32_t* triangle) {
  const TinyResult r = tiny_test<false>(s, rays, tfar);
  const IV unsure = (r.other_lo < splat(__builtin_inff())) & (r.other_lo <= r.best + r.best_err);
  std::memcpy(triangle, &r.id, sizeof r.id);
  return lane_mask(unsure);
}

inline uint32_t tiny_occluded(const TinyScene& s, const float* const* rays, const float* tfar, bool* blocked) {
  const TinyResult r = tiny_test<true>(s, rays, tfar);
  const FV inf = splat(__builtin_inff());
  const IV hit = r.best < inf;
  const uint32_t m = lane_mask(hit);
  for (int i = 0; i < kLanes; ++i) blocked[i] = (m >> i) & 1;
  return lane_mask(~hit & (r.other_lo < inf));
}

}  // namespace pb::cpu::PB_SIMD_NS
