#pragma once
// The geometry of a hit, recomputed from the triangle id alone. Intersectors (Embree
// on the CPU, the BVH traversal on the GPU) only decide WHICH triangle a ray hits;
// this one function then computes where, in the path step's precision. Strategies that
// intersect in packets or streams therefore see bit-identical hit points, and CPU and
// GPU differ only where they pick a different triangle.
#include <cstdint>

#include "pathbench/common/camera.h"
#include "pathbench/common/scene.h"

namespace pb {

template <class T> struct SurfaceHit {
  Vec3<T> p;         // on the triangle's plane, from barycentrics
  Vec3<T> ng;        // unit geometric normal, cross(v1 - v0, v2 - v0)
  T t;               // distance along the (unit) ray direction
  uint32_t prim;
};

template <class T> PB_HD SurfaceHit<T> surface_hit(const SceneView& s, uint32_t prim, const Ray<T>& ray) {
  const Triangle tri = s.triangles[prim];
  const Vec3<T> v0 = Vec3<T>(s.positions[tri.v[0]]);
  const Vec3<T> e1 = Vec3<T>(s.positions[tri.v[1]]) - v0;
  const Vec3<T> e2 = Vec3<T>(s.positions[tri.v[2]]) - v0;
  // Moeller-Trumbore without rejection: the intersector already accepted this hit.
  // (Fused: fdot / fcross, as the rest of the path step.)
  Vec3<T> pv = fcross(ray.d, e2);
  T inv_det = T(1) / fdot(e1, pv);
  Vec3<T> tv = ray.o - v0;
  T b1 = fdot(tv, pv) * inv_det;
  Vec3<T> qv = fcross(tv, e1);
  T b2 = fdot(ray.d, qv) * inv_det;
  T t = fdot(e2, qv) * inv_det;
  // Clamp into the triangle: a hit found exactly on an edge may land a rounding
  // error outside it.
  b1 = pmin(pmax(b1, T(0)), T(1));
  b2 = pmin(pmax(b2, T(0)), T(1) - b1);
  SurfaceHit<T> h;
  h.p = fmadd(e2, b2, fmadd(e1, b1, v0));
  h.ng = fnormalize(fcross(e1, e2));
  h.t = t;
  h.prim = prim;
  return h;
}

}  // namespace pb
