// What the tracers' instanced acceleration structures (--instancing) need to know of a
// SceneInstance beyond its record: where its prototype sits in traced coordinates, and how
// far its flat copy (expanded on load, rounded to float, maybe rebased or rescaled) lies
// from that exact image of the prototype.
#include <algorithm>
#include <cmath>

#include "pathbench/common/scene.h"

namespace pb {

Affine traced_to_world(const Scene& s, const SceneInstance& in) {
  // Traced coordinates are the user's less Scene::origin (scene_origin.cpp); the flat
  // positions went through that rebase, the instance's to_world did not.
  return Affine::translate(-double(s.origin.x), -double(s.origin.y), -double(s.origin.z)) * in.to_world;
}

double instance_deviation(const Scene& s, const SceneInstance& in) {
  const ScenePrototype& p = s.prototypes.at(in.prototype);
  if (in.triangle_count != p.triangles.size()) return INFINITY;
  const Affine m = traced_to_world(s, in);
  double dev = 0;
  for (uint32_t k = 0; k < in.triangle_count; ++k) {
    const Triangle& ft = s.triangles[in.first_triangle + k];
    const Triangle& pt = p.triangles[k];
    for (uint32_t fv : ft.v) {
      const Vec3f f = s.positions[fv];
      double nearest = INFINITY;  // the matching vertex (a mirrored copy's winding is flipped)
      for (uint32_t pv : pt.v) {
        const Vec3f q = p.positions[pv];
        double d = 0;
        for (int r = 0; r < 3; ++r) {
          const double x = m.m[r][0] * q.x + m.m[r][1] * q.y + m.m[r][2] * q.z + m.m[r][3];
          d = std::max(d, std::fabs(x - double(f[r])));
        }
        nearest = std::min(nearest, d);
      }
      dev = std::max(dev, nearest);
    }
  }
  return dev;
}

}  // namespace pb
