#pragma once
// Conversions between the path step's rays and Embree's ray structures.
#include <embree3/rtcore.h>

#include <cstring>
#include <limits>
#include <type_traits>

#include "pathbench/common/camera.h"
#include "pathbench/common/watertight.h"
#include "pathbench/cpu/embree_scene.h"
#include "shade_batch.h"

namespace pb::cpu {

// Embree counts a hit at tnear <= t; the path step's (and the GPU's watertight test's)
// hits are at t > ray_t_min(o, d) (watertight.h: hits at the ray's own origin do not
// count). Embree gets that as tnear, computed from the float ray Embree sees. With
// tnear = 0 a ray leaving a corner of two surfaces (offset off one, still in the plane of
// the other) met that plane at t = 0 or -0 in Embree's arithmetic: a shadow ray blocked on
// the CPU and clear on the GPU (most of the 13-16 pixels of 65,536 at which the CPU's and
// the GPU's paper-cornell 256x256x800 films differed).
inline float embree_tnear(float ox, float oy, float oz, float dx, float dy, float dz) {
  return ray_t_min(Vec3f{ox, oy, oz}, Vec3f{dx, dy, dz});
}

// Embree traces in float: a double ray is rounded to float here.
template <class T> inline void to_embree(const Ray<T>& r, float tfar, RTCRay& e) {
  e.org_x = float(r.o.x); e.org_y = float(r.o.y); e.org_z = float(r.o.z);
  e.dir_x = float(r.d.x); e.dir_y = float(r.d.y); e.dir_z = float(r.d.z);
  e.tnear = embree_tnear(e.org_x, e.org_y, e.org_z, e.dir_x, e.dir_y, e.dir_z);
  e.tfar = tfar;
  e.time = 0.0f;
  e.mask = 0xFFFFFFFFu;
  e.id = 0;
  e.flags = 0;
}

template <int N, class T> inline void set_lane(RTCRayNt<N>& p, int i, const Ray<T>& r, float tfar) {
  p.org_x[i] = float(r.o.x); p.org_y[i] = float(r.o.y); p.org_z[i] = float(r.o.z);
  p.dir_x[i] = float(r.d.x); p.dir_y[i] = float(r.d.y); p.dir_z[i] = float(r.d.z);
  // tnear: set by intersect_packet / occluded_packet for every active lane (set_tnear).
  p.tfar[i] = tfar;
  p.time[i] = 0.0f;
  p.mask[i] = 0xFFFFFFFFu;
  p.id[i] = 0;
  p.flags[i] = 0;
}

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// The scene triangle the ray hits first (t > 0), or RTC_INVALID_GEOMETRY_ID: one
// rtcIntersect1, its hit mapped back to the scene's triangle (the layout may be quads).
template <class T> inline uint32_t closest_triangle(const EmbreeScene& e, RTCIntersectContext& ctx, const Ray<T>& r) {
  RTCRayHit rh;
  to_embree(r, kInfinity, rh.ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(e.handle(), &ctx, &rh);
  return rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? RTC_INVALID_GEOMETRY_ID : e.triangle(rh.hit);
}

// Whether anything blocks the ray before t = tfar (one rtcOccluded1).
template <class T> inline bool occluded(const EmbreeScene& e, RTCIntersectContext& ctx, const Ray<T>& r, float tfar) {
  RTCRay sr;
  to_embree(r, tfar, sr);
  rtcOccluded1(e.handle(), &ctx, &sr);
  return sr.tfar < 0.0f;  // Embree marks an occluded ray with tfar = -inf
}

// Packets of 8 or 16 rays (the batched path step's widths: AVX2, AVX-512), lanes [0, n)
// active: every caller fills its packet from lane 0. The shading kernels write the rays'
// arrays directly, so each call sets the active lanes' tnear from their rays first.
template <int W> void set_tnear(int n, RTCRayNt<W>& p) {
  for (int i = 0; i < n; ++i)
    p.tnear[i] = embree_tnear(p.org_x[i], p.org_y[i], p.org_z[i], p.dir_x[i], p.dir_y[i], p.dir_z[i]);
}
template <int W> struct LaneMask {
  alignas(64) int valid[W];
  explicit LaneMask(int n) {
    for (int i = 0; i < W; ++i) valid[i] = i < n ? -1 : 0;
  }
};
inline void intersect_packet(int n, RTCScene s, RTCIntersectContext* c, RTCRayHitNt<8>& p) {
  set_tnear(n, p.ray);
  rtcIntersect8(LaneMask<8>(n).valid, s, c, reinterpret_cast<RTCRayHit8*>(&p));
}
inline void intersect_packet(int n, RTCScene s, RTCIntersectContext* c, RTCRayHitNt<16>& p) {
  set_tnear(n, p.ray);
  rtcIntersect16(LaneMask<16>(n).valid, s, c, reinterpret_cast<RTCRayHit16*>(&p));
}
inline void occluded_packet(int n, RTCScene s, RTCIntersectContext* c, RTCRayNt<8>& p) {
  set_tnear(n, p);
  rtcOccluded8(LaneMask<8>(n).valid, s, c, reinterpret_cast<RTCRay8*>(&p));
}
inline void occluded_packet(int n, RTCScene s, RTCIntersectContext* c, RTCRayNt<16>& p) {
  set_tnear(n, p);
  rtcOccluded16(LaneMask<16>(n).valid, s, c, reinterpret_cast<RTCRay16*>(&p));
}

// Packet fields that stay as set: everything but the ray, tfar and the hit. The rays start
// at zero: the tiny test (tiny_x8.h) reads every lane, the inactive ones too (their rays
// from earlier calls, or these zeros), never uninitialised memory (valgrind: its skips
// branched on it; the answers of the active lanes do not depend on the others').
template <int W> void init_packet_constants(RTCRayNt<W>& r) {
  for (int i = 0; i < W; ++i) {
    r.org_x[i] = r.org_y[i] = r.org_z[i] = r.dir_x[i] = r.dir_y[i] = r.dir_z[i] = 0.0f;
    r.tnear[i] = 0.0f;  // set per call from the rays (set_tnear)
    r.time[i] = 0.0f;
    r.mask[i] = 0xFFFFFFFFu;
    r.id[i] = 0;
    r.flags[i] = 0;
  }
}

// A packet's per-call fields at their start values: tfar (infinity for closest hits, 1 for
// shadow rays, whose direction spans the segment) and the hit's geomID. Only Embree changes
// them, so a tracer that keeps its packets resets them after each Embree call, not before
// every call (the tiny-scene test reads tfar and leaves it).
template <int W> void reset_packet(RTCRayHitNt<W>& p) {
  for (int i = 0; i < W; ++i) {
    p.ray.tfar[i] = kInfinity;
    p.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
  }
}
template <int W> void reset_packet(RTCRayNt<W>& p) {
  for (int i = 0; i < W; ++i) p.tfar[i] = 1.0f;
}

// The scene triangle a packet's lane i hit (after intersect_packet), or RTC_INVALID_GEOMETRY_ID.
template <int W> inline uint32_t packet_triangle(const EmbreeScene& e, const RTCRayHitNt<W>& p, int i) {
  return p.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? RTC_INVALID_GEOMETRY_ID
                                                    : e.triangle(p.hit.instID[0][i], p.hit.primID[i], p.hit.u[i], p.hit.v[i]);
}

// Rays kept as six arrays (org x, y, z, dir x, y, z: the shading kernel's streams,
// ShadeStream) into packet `p`, unless they are its own arrays already.
template <int W> void copy_rays(const float* const* rays, RTCRayNt<W>& p) {
  float* const out[6] = {p.org_x, p.org_y, p.org_z, p.dir_x, p.dir_y, p.dir_z};
  for (int j = 0; j < 6; ++j)
    if (rays[j] != out[j]) std::memcpy(out[j], rays[j], sizeof(float) * W);
}
// A packet's ray arrays, as the kernels' streams and the tiny test name them.
template <int W> void packet_arrays(RTCRayNt<W>& p, float** out) {
  out[0] = p.org_x; out[1] = p.org_y; out[2] = p.org_z;
  out[3] = p.dir_x; out[4] = p.dir_y; out[5] = p.dir_z;
}

}  // namespace pb::cpu
