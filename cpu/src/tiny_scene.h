#pragma once
// Tiny scenes ("model only what a scene requires"): for a scene of a few dozen triangles
// Embree's robust traversal costs ~600 instructions per closest-hit ray (docs/notes/cpu-log.md),
// while testing every triangle against a packet of rays, lanes = rays, costs a fraction
// of that. TinyScene is the table such a test reads (the triangles in the vertex order
// Embree's own Pluecker test sees them, so the arithmetic is Embree's); the test itself
// is tiny_x8.h (AVX2 / AVX-512, through BatchKernels).
//
// The test never guesses. For each ray it either proves Embree's answer -- the hit
// triangle of a closest-hit query, or whether a shadow ray is blocked -- or it marks the
// ray "unsure", and the caller asks Embree for that ray (tiny_closest / tiny_occluded
// below). Unsure: a candidate near an edge of its triangle (inside or out), a hit whose
// distance is within a small relative margin of another candidate's (ties), of the ray's
// tfar, or of its origin (the surface the ray leaves from), where Embree's rounding could
// decide either way. The margins are far above the float error of Embree's formulas and
// of ours (docs/notes/cpu-log.md gives the bounds), so a proven answer is Embree's answer.
#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "embree_rays.h"
#include "pathbench/common/scene.h"
#include "pathbench/cpu/embree_scene.h"
#include "shade_batch.h"
#include "stage_timers.h"

namespace pb::cpu {

struct TinyScene {
  // Above a weight of 3 per lane (24 with AVX2, 48 with AVX-512) Embree's BVH is cheaper
  // than testing every triangle. The weight: one per general triangle (as Embree sees them;
  // AVX2 measured between 14 and 34, AVX-512, whose test costs half per ray, estimated),
  // one half per axis-plane group (AVX2, pixel, callgrind: 19 and 31 groups 0.65x Embree's
  // instructions, 55 groups 0.97x; cornell-box 0.69x, paper-cornell-ico:0 0.64x, ico:1 2.2x;
  // docs/notes/cpu-log.md, 2026-11-27, part 2).
  static constexpr int kTrianglesPerLane = 3;
  size_t weight() const { return general.size() + (groups.size() + 1) / 2; }
  struct alignas(64) Triangle {
    float p[9];         // vertices v0, v1, v2 in Embree's order
    uint32_t triangle;  // the scene triangle
    float edge;         // its largest |edge component| (error bounds)
    // Its plane, for the plane cull (tiny_x8.h `plane_away`): unit normal n and offset c
    // (n . x = c on the plane, both rounded to float), and the cull's margin per unit of
    // scale: 2^-15 (1 + 2 E^2 / |Ng|) (Embree's normal's rounding grows with E^2 / |Ng|,
    // a sliver's) plus the float plane's own miss of the vertices over pmax (the scale is
    // >= pmax). k = inf: never culled. 16 floats: a table row is one cache line.
    float n[3], c, cull_k;
  };
  static_assert(sizeof(Triangle) == 64);
  std::vector<Triangle> triangles;
  float lo[3], hi[3];  // bounds of every vertex
  float pmax;          // largest |vertex coordinate| (the cull's scale)

  // The axis-plane test (tiny_x8.h; docs/notes/cpu-log.md, 2026-11-27 "issue 35, part 2",
  // gives the error argument). A triangle whose three vertices share one coordinate exactly
  // (x_k = P: a wall of a box) is tested without Embree's arithmetic: for it Embree's
  // normal has exact zeros off axis k, so Embree's t is (P - o_k) / D_k up to a few
  // roundings whatever its normal's own rounding, and its edge functions are a 2D test in
  // the plane, bounded here against exact arithmetic (Embree's error and ours). Two such
  // triangles of one plane in a row (a quad's halves) form one group: one t and one
  // in-plane point for both. Every other triangle (`general`) gets Embree's formulas, as
  // before.
  struct alignas(64) AxisGroup {
    int32_t k, i, j, count;  // normal axis, the two in-plane axes; 1 or 2 triangles
    float P, Ri, Rj;         // the plane x_k = P; a vertex R of the group (in-plane i, j)
    uint32_t id[2];          // scene triangles
    // Per triangle and edge: f = n_i Y_i + n_j Y_j + c, Y = X - R (X: where the ray meets
    // the plane), twice the signed area of (edge, X), oriented so that f > 0 inside.
    float e[2][3][3];
    float pad[5];
  };
  static_assert(sizeof(AxisGroup) == 128);
  std::vector<AxisGroup> groups;
  std::vector<uint32_t> general;  // the other rows of `triangles`
  float axis_e = 0.0f;     // largest |edge component| of the grouped triangles
  float axis_m_ok = 0.0f;  // a ray uses the axis-plane test only where M <= this (min 2^14 A / E)
  float axis_o_ok = -1.0f; // ... checked as |o|_inf <= this (M <= |o|_inf + pmax)

  // A triangle in a plane x_k = P, where it qualifies (the ranges the error argument needs:
  // coordinates at most 2^20, P zero or at least 2^-20, A in [2^-20, 2^40], no sliver:
  // A >= 2^-19 E^2).
  struct AxisTri {
    int k = -1, i = 0, j = 0;
    double P = 0.0, q[3][2] = {}, sg = 1.0, A = 0.0, E = 0.0;
  };
  static AxisTri axis_tri(const Triangle& r) {
    AxisTri a;
    int k = -1;
    for (int c = 0; c < 3; ++c)
      if (r.p[c] == r.p[3 + c] && r.p[c] == r.p[6 + c]) k = (k == -1 ? c : 3);
    if (k < 0 || k > 2) return a;
    for (float x : r.p)
      if (!(std::fabs(x) <= 0x1p20f)) return a;
    const double P = r.p[k];
    if (P != 0.0 && std::fabs(P) < 0x1p-20) return a;
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    for (int v = 0; v < 3; ++v) a.q[v][0] = r.p[3 * v + i], a.q[v][1] = r.p[3 * v + j];
    const double area2 = (a.q[1][0] - a.q[0][0]) * (a.q[2][1] - a.q[0][1]) - (a.q[1][1] - a.q[0][1]) * (a.q[2][0] - a.q[0][0]);
    a.A = std::fabs(area2);
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 2; ++c) a.E = std::max(a.E, std::fabs(a.q[(v + 1) % 3][c] - a.q[v][c]));
    if (!(a.A >= 0x1p-20 && a.A <= 0x1p40 && a.A >= 0x1p-19 * a.E * a.E)) return a;
    a.sg = area2 > 0.0 ? 1.0 : -1.0;
    a.k = k, a.i = i, a.j = j, a.P = P;
    return a;
  }
  // Triangle t's edges relative to R into g.e[h]: edge a -> b: n = sg (-(b - a)_j, (b - a)_i),
  // c = n . (R - a), in double, rounded once.
  static void set_edges(AxisGroup& g, int h, const AxisTri& t, double Ri, double Rj) {
    for (int e = 0; e < 3; ++e) {
      const double* a = t.q[e];
      const double* b = t.q[(e + 1) % 3];
      const double ni = -t.sg * (b[1] - a[1]), nj = t.sg * (b[0] - a[0]);
      g.e[h][e][0] = float(ni);
      g.e[h][e][1] = float(nj);
      g.e[h][e][2] = float(ni * (Ri - a[0]) + nj * (Rj - a[1]));
    }
  }
  // The groups and the general rows of the table.
  void set_axis_groups() {
    std::vector<AxisTri> at;
    for (const Triangle& r : triangles) at.push_back(axis_tri(r));
    double e_max = 0.0, m_ok = 0x1p100;
    for (const AxisTri& a : at)
      if (a.k >= 0) e_max = std::max(e_max, a.E), m_ok = std::min(m_ok, 0x1p14 * a.A / a.E);
    for (size_t r = 0; r < triangles.size(); ++r) {
      const AxisTri& a = at[r];
      if (a.k < 0) {
        general.push_back(uint32_t(r));
        continue;
      }
      AxisGroup g{};
      g.k = a.k, g.i = a.i, g.j = a.j, g.P = float(a.P);
      g.Ri = float(a.q[0][0]), g.Rj = float(a.q[0][1]);
      g.count = 1;
      g.id[0] = g.id[1] = triangles[r].triangle;
      set_edges(g, 0, a, a.q[0][0], a.q[0][1]);
      // The next row in the same plane joins when its vertices lie within 2 E of R (the
      // error argument's bound on |vertex - R|).
      if (r + 1 < triangles.size()) {
        const AxisTri& b = at[r + 1];
        bool near = b.k == a.k && b.P == a.P;
        for (int v = 0; v < 3 && near; ++v)
          near = std::fabs(b.q[v][0] - a.q[0][0]) <= 2.0 * e_max && std::fabs(b.q[v][1] - a.q[0][1]) <= 2.0 * e_max;
        if (near) {
          g.count = 2;
          g.id[1] = triangles[r + 1].triangle;
          set_edges(g, 1, b, a.q[0][0], a.q[0][1]);
          ++r;
        }
      }
      groups.push_back(g);
    }
    if (!groups.empty()) {
      axis_e = std::nextafter(float(e_max), __builtin_inff());  // rounded up
      axis_m_ok = std::nextafter(float(m_ok), 0.0f);            // rounded down
      axis_o_ok = std::nextafter(float((m_ok - double(pmax)) * (1.0 - 0x1p-20)), -1.0f);
    }
  }

  // r's plane in double, rounded to float; a degenerate triangle is never culled.
  static void set_plane(Triangle& r, double pmax) {
    double a[3], b[3], c[3];
    for (int j = 0; j < 3; ++j) a[j] = r.p[j], b[j] = r.p[3 + j], c[j] = r.p[6 + j];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double ng[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double len = std::sqrt(ng[0] * ng[0] + ng[1] * ng[1] + ng[2] * ng[2]);
    r.n[0] = r.n[1] = r.n[2] = r.c = 0.0f;
    r.cull_k = __builtin_inff();
    if (!(len > 0.0) || !std::isfinite(len) || !(pmax > 0.0)) return;
    for (int j = 0; j < 3; ++j) r.n[j] = float(ng[j] / len);
    r.c = float(double(r.n[0]) * a[0] + double(r.n[1]) * a[1] + double(r.n[2]) * a[2]);
    double rho = 0.0;
    for (const double* q : {a, b, c})
      rho = std::max(rho, std::fabs(double(r.n[0]) * q[0] + double(r.n[1]) * q[1] + double(r.n[2]) * q[2] - double(r.c)));
    r.cull_k = float(0x1p-15 * (1.0 + 2.0 * double(r.edge) * double(r.edge) / len) + (2.0 * rho + 0x1p-30) / pmax);
  }

  // The table for the Embree scene `e` of `s`, or null where its weight is above
  // `max_weight`.
  // Quads are split as Embree splits them: (v0, v1, v3), then (v2, v3, v1); the empty
  // second half of a lone triangle's quad (a, b, c, c) is left out (Embree never hits it:
  // its normal is zero).
  static std::unique_ptr<TinyScene> build(const EmbreeScene& e, const SceneView& s, size_t max_weight) {
    // At most 4 triangles (two groups of two) a unit of weight: larger scenes are never built.
    const TrianglePairs* pairs = e.pairs();
    if ((pairs ? 2 * pairs->quads.size() : size_t(s.num_triangles)) > 4 * max_weight + 1) return nullptr;
    auto t = std::make_unique<TinyScene>();
    auto add = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t tri) {
      Triangle r;
      const Vec3f v[3] = {s.positions[a], s.positions[b], s.positions[c]};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.p[3 * i + j] = v[i][j];
      r.triangle = tri;
      r.edge = 0.0f;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r.edge = std::max(r.edge, std::fabs(v[(i + 1) % 3][j] - v[i][j]));
      t->triangles.push_back(r);
    };
    if (pairs) {
      for (size_t q = 0; q < pairs->quads.size(); ++q) {
        const auto& v = pairs->quads[q];
        add(v[0], v[1], v[3], pairs->triangle[2 * q]);
        if (v[2] != v[3]) add(v[2], v[3], v[1], pairs->triangle[2 * q + 1]);
      }
    } else {
      for (uint32_t i = 0; i < s.num_triangles; ++i) add(s.triangles[i].v[0], s.triangles[i].v[1], s.triangles[i].v[2], i);
    }
    if (t->triangles.empty()) return nullptr;
    for (int j = 0; j < 3; ++j) {
      t->lo[j] = t->hi[j] = t->triangles[0].p[j];
      for (const Triangle& r : t->triangles)
        for (int i = 0; i < 3; ++i) {
          t->lo[j] = std::min(t->lo[j], r.p[3 * i + j]);
          t->hi[j] = std::max(t->hi[j], r.p[3 * i + j]);
        }
    }
    t->pmax = 0.0f;
    for (int j = 0; j < 3; ++j) t->pmax = std::max({t->pmax, std::fabs(t->lo[j]), std::fabs(t->hi[j])});
    for (Triangle& r : t->triangles) set_plane(r, t->pmax);
    t->set_axis_groups();
    if (t->weight() > max_weight) return nullptr;
    return t;
  }
};

// The tiny test where it applies: batched kernels `k` (a vector ISA; AVX2 needs FMA too,
// as Embree's AVX2 kernels do) and a scene of weight at most kTrianglesPerLane per lane;
// otherwise null.
inline std::unique_ptr<TinyScene> tiny_scene_for(const EmbreeScene& e, const SceneView& s, const BatchKernels* k) {
  if (!k || !__builtin_cpu_supports("fma")) return nullptr;
  return TinyScene::build(e, s, size_t(TinyScene::kTrianglesPerLane * k->lanes));
}

// Lane i of the six ray arrays (org x, y, z, dir x, y, z) as one ray.
inline Ray<float> lane_ray(const float* const* rays, int i) {
  return {{rays[0][i], rays[1][i], rays[2][i]}, {rays[3][i], rays[4][i], rays[5][i]}};
}

// The closest hits of the rays `rays` (six arrays of W: org x, y, z, dir x, y, z; lanes
// [0, n) valid; W = k.lanes) with packet `p`'s tfar: the tiny test, and for each lane it
// leaves unsure, Embree for that ray alone (rtcIntersect1, trace_path's query). Not Embree's
// packet: its answer for a ray exactly at an edge or at tfar depends on the packet's other
// active lanes (how many there are: the packet and the single-ray traversals round
// differently; TinyIsa.AnswersDoNotDependOnPacketMates found rays blocked in a packet of 16
// and clear alone), and which rays share a packet depends on the rank's share of the samples
// (issue 30). A ray's answer is then its own whatever its packet: the test's proven answer,
// or Embree's single-ray one. prim[i]: the scene triangle, or RTC_INVALID_GEOMETRY_ID.
// Returns the number of unsure lanes; `p` is not changed.
template <int W>
int tiny_closest(const BatchKernels& k, const TinyScene& t, const EmbreeScene& e, RTCIntersectContext& ctx,
                 const float* const* rays, RTCRayHitNt<W>& p, int n, uint32_t* prim) {
  const uint32_t unsure = k.tiny_closest(t, rays, p.ray.tfar, prim) & uint32_t((uint64_t(1) << n) - 1);
  if (unsure == 0) return 0;
  PB_STAGE(kClosestEmbree);
  for (uint32_t u = unsure; u != 0; u &= u - 1) {
    const int i = __builtin_ctz(u);
    prim[i] = closest_triangle(e, ctx, lane_ray(rays, i));
  }
  return __builtin_popcount(unsure);
}

// Whether each shadow ray of `rays` (as tiny_closest; tfar: packet `p`'s) is blocked:
// the tiny test, then (as tiny_closest) Embree for each ray it left unsure alone
// (rtcOccluded1 up to its tfar). Returns the number of unsure lanes; `p` is not changed.
template <int W>
int tiny_occluded(const BatchKernels& k, const TinyScene& t, const EmbreeScene& e, RTCIntersectContext& ctx,
                  const float* const* rays, RTCRayNt<W>& p, int n, bool* blocked) {
  const uint32_t unsure = k.tiny_occluded(t, rays, p.tfar, blocked) & uint32_t((uint64_t(1) << n) - 1);
  if (unsure == 0) return 0;
  PB_STAGE(kShadowEmbree);
  for (uint32_t u = unsure; u != 0; u &= u - 1) {
    const int i = __builtin_ctz(u);
    blocked[i] = occluded(e, ctx, lane_ray(rays, i), p.tfar[i]);
  }
  return __builtin_popcount(unsure);
}

// Embree's closest hits for packet p's lanes [0, n) (rays and tfar set), as scene
// triangles (or RTC_INVALID_GEOMETRY_ID) in prim; p's tfar and geomID reset after.
template <int W> void embree_closest(const EmbreeScene& e, RTCIntersectContext& ctx, RTCRayHitNt<W>& p, int n, uint32_t* prim) {
  intersect_packet(n, e.handle(), &ctx, p);
  for (int i = 0; i < n; ++i) prim[i] = packet_triangle(e, p, i);
  reset_packet(p);
}
// Embree's answer whether each of packet p's shadow rays [0, n) is blocked; tfar reset after.
template <int W> void embree_occluded(const EmbreeScene& e, RTCIntersectContext& ctx, RTCRayNt<W>& p, int n, bool* blocked) {
  occluded_packet(n, e.handle(), &ctx, p);
  for (int i = 0; i < n; ++i) blocked[i] = p.tfar[i] < 0.0f;
  reset_packet(p);
}

// The batched strategies' packets, their rays as six arrays (p's own or the caller's,
// e.g. the shading's streams) and p's tfar / geomID at their start values: the tiny
// test first where there is one, otherwise Embree (the rays copied into p).
template <int W>
void closest_hits(const BatchKernels& k, const TinyScene* tiny, const EmbreeScene& e, RTCIntersectContext& ctx,
                  const float* const* rays, RTCRayHitNt<W>& p, int n, uint32_t* prim) {
  if (tiny) {
    tiny_closest<W>(k, *tiny, e, ctx, rays, p, n, prim);
    return;
  }
  copy_rays<W>(rays, p.ray);
  embree_closest<W>(e, ctx, p, n, prim);
}
template <int W>
void shadows_blocked(const BatchKernels& k, const TinyScene* tiny, const EmbreeScene& e, RTCIntersectContext& ctx,
                     const float* const* rays, RTCRayNt<W>& p, int n, bool* blocked) {
  if (tiny) {
    tiny_occluded<W>(k, *tiny, e, ctx, rays, p, n, blocked);
    return;
  }
  copy_rays<W>(rays, p);
  embree_occluded<W>(e, ctx, p, n, blocked);
}

}  // namespace pb::cpu
