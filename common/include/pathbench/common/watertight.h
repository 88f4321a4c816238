#pragma once
// Watertight ray/triangle intersection (Woop, Benthin, Wald, "Watertight Ray/Triangle
// Intersection", JCGT 2013), host+device. The ray is sheared so that it runs along +z
// from the origin; the 2D edge functions U, V, W of the sheared triangle then decide
// the hit. Edge functions that come out exactly 0 are recomputed in double, so a ray
// through a shared edge or vertex hits at least one of the triangles that meet there,
// on the CPU and the GPU alike. Woop's t (a barycentric mean of the vertices' sheared
// depths) is good enough to order candidates, but its weights cancel on grazing rays;
// closest-hit traversal replaces the winner's t with plane_distance.
//
// Only IEEE +, -, *, / are used (no fused multiply-add: the GPU library is compiled
// with --fmad=false), so the host and the device compute bit-identical results.
#include <cstdint>

#include "pathbench/common/hd.h"
#include "pathbench/common/math.h"

namespace pb {

// Per-ray constants of the shear transform.
struct WatertightRay {
  Vec3f o;
  int kx, ky, kz;
  float sx, sy, sz;
};

// The least t a hit needs, along the ray's own (unnormalised) direction: about 4 float
// ulps of the origin's largest coordinate, as a distance. A ray leaving a corner of two
// surfaces is offset off the one it hit (ray_offset.h) but still lies in the plane of the
// other; heading out through that plane it meets it at t = 0 exactly, which rounding
// turns into a tiny t of either sign (1e-12 .. 5e-7 seen in paper-cornell), hit or not
// by the noise of each device's arithmetic. Such hits are the ray's own origin, not
// geometry in front of it: every triangle test here and the CPU's Embree rays
// (tnear, cpu/src/embree_rays.h) skip them alike. Far below the origin offset (256
// ulps), so no surface the offset cleared is ever skipped.
PB_HD float ray_t_min(const Vec3f& o, const Vec3f& d) {
  const float dmax = max_component(vabs(d));
  return dmax > 0.0f ? 0x1p-21f * max_component(vabs(o)) * (1.0f / dmax) : 0.0f;
}

PB_HD float wt_axis(const Vec3f& v, int k) { return k == 0 ? v.x : (k == 1 ? v.y : v.z); }

PB_HD WatertightRay make_watertight_ray(const Vec3f& o, const Vec3f& d) {
  WatertightRay r;
  r.o = o;
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  int kz = 2;
  if (ax > ay && ax > az) kz = 0;
  else if (ay > az) kz = 1;
  int kx = kz + 1 == 3 ? 0 : kz + 1;
  int ky = kx + 1 == 3 ? 0 : kx + 1;
  const float dz = wt_axis(d, kz);
  if (dz < 0.0f) {  // keep the winding: swap kx and ky
    const int t = kx;
    kx = ky;
    ky = t;
  }
  r.kx = kx;
  r.ky = ky;
  r.kz = kz;
  r.sx = wt_axis(d, kx) / dz;
  r.sy = wt_axis(d, ky) / dz;
  r.sz = 1.0f / dz;
  return r;
}

// ray_t_min of the ray r was made from, bit for bit: |sz| = 1 / |d|_inf, as d's dominant
// axis is kz. Evaluated where a hit is found rather than kept per ray: one more live
// register cost the GPU's megakernel spills (ptxas sm_90: 48 -> 56 bytes stored) and 5 %.
PB_HD float t_min_of(const WatertightRay& r) {
  return 0x1p-21f * max_component(vabs(r.o)) * std::fabs(r.sz);
}

// The distance along d from o to the plane of (a, b, c), rounded once from double.
// Woop's t loses up to 1e-2 relative on grazing rays; the plane equation in double, from
// the same float inputs, comes within one float ulp of the exact t unless the ray is
// parallel to the plane to within about 1e-8 rad. Evaluated once per closest hit (every
// candidate would cost the GPU's megakernel 6%).
PB_HD float plane_distance(const Vec3f& o, const Vec3f& d, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const double ax = a.x, ay = a.y, az = a.z;
  const double e1x = double(b.x) - ax, e1y = double(b.y) - ay, e1z = double(b.z) - az;
  const double e2x = double(c.x) - ax, e2y = double(c.y) - ay, e2z = double(c.z) - az;
  const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
  const double num = nx * (ax - double(o.x)) + ny * (ay - double(o.y)) + nz * (az - double(o.z));
  const double den = nx * double(d.x) + ny * double(d.y) + nz * double(d.z);
  return float(num / den);
}

// Tests the triangle (a, b, c) for a hit with ray_t_min < t < t_max (t along the ray's own,
// unnormalised direction). On a hit returns true and sets t.
PB_HD bool intersect_watertight(const WatertightRay& r, const Vec3f& a, const Vec3f& b, const Vec3f& c,
                                float t_max, float& t) {
  const Vec3f A = a - r.o, B = b - r.o, C = c - r.o;
  const float Az = wt_axis(A, r.kz), Bz = wt_axis(B, r.kz), Cz = wt_axis(C, r.kz);
  const float Ax = wt_axis(A, r.kx) - r.sx * Az, Ay = wt_axis(A, r.ky) - r.sy * Az;
  const float Bx = wt_axis(B, r.kx) - r.sx * Bz, By = wt_axis(B, r.ky) - r.sy * Bz;
  const float Cx = wt_axis(C, r.kx) - r.sx * Cz, Cy = wt_axis(C, r.ky) - r.sy * Cz;
  float U = Cx * By - Cy * Bx;
  float V = Ax * Cy - Ay * Cx;
  float W = Bx * Ay - By * Ax;
  if (U == 0.0f || V == 0.0f || W == 0.0f) {
    // Exactly on an edge in float: decide in double, where these products are exact.
    U = float(double(Cx) * double(By) - double(Cy) * double(Bx));
    V = float(double(Ax) * double(Cy) - double(Ay) * double(Cx));
    W = float(double(Bx) * double(Ay) - double(By) * double(Ax));
  }
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;
  const float T = U * (r.sz * Az) + V * (r.sz * Bz) + W * (r.sz * Cz);
  // 0 < T / det < t_max without dividing (both sides of the sign of det).
  if (det > 0.0f) {
    if (!(T > 0.0f) || !(T < t_max * det)) return false;
  } else {
    if (!(T < 0.0f) || !(T > t_max * det)) return false;
  }
  t = T / det;
  return t > t_min_of(r) && t < t_max;
}

}  // namespace pb
