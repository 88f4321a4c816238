#pragma once
// Moeller-Trumbore ray/triangle test (1997), the paper's intersector: fast, but not
// watertight (a ray through an edge shared by two triangles can miss both, since each
// triangle's edge test rounds on its own). Kept beside watertight.h so the accuracy
// study can measure what watertightness buys; the tracers use watertight.h by default.
#include "pathbench/common/math.h"

namespace pb {

// Hit for t_min < t < t_max along d (need not be unit length); t receives the distance.
PB_HD bool intersect_moller_trumbore(const Vec3f& o, const Vec3f& d, const Vec3f& v0, const Vec3f& v1,
                                            const Vec3f& v2, float t_max, float& t) {
  const Vec3f e1 = v1 - v0, e2 = v2 - v0;
  const Vec3f pv = cross(d, e2);
  const float det = dot(e1, pv);
  if (det == 0.0f) return false;  // ray parallel to the plane
  const float inv_det = 1.0f / det;
  const Vec3f tv = o - v0;
  const float b1 = dot(tv, pv) * inv_det;
  if (b1 < 0.0f || b1 > 1.0f) return false;
  const Vec3f qv = cross(tv, e1);
  const float b2 = dot(d, qv) * inv_det;
  if (b2 < 0.0f || b1 + b2 > 1.0f) return false;
  const float th = dot(e2, qv) * inv_det;
  if (!(th > 0.0f && th < t_max)) return false;
  t = th;
  return true;
}

}  // namespace pb
