#pragma once
// Conversions between the path step's rays and Embree's ray structures.
#include <embree3/rtcore.h>

#include <limits>

#include "pathbench/common/camera.h"

namespace pb::cpu {

inline void to_embree(const Ray<float>& r, float tfar, RTCRay& e) {
  e.org_x = r.o.x; e.org_y = r.o.y; e.org_z = r.o.z;
  e.dir_x = r.d.x; e.dir_y = r.d.y; e.dir_z = r.d.z;
  e.tnear = 0.0f;
  e.tfar = tfar;
  e.time = 0.0f;
  e.mask = 0xFFFFFFFFu;
  e.id = 0;
  e.flags = 0;
}

template <int N> inline void set_lane(RTCRayNt<N>& p, int i, const Ray<float>& r, float tfar) {
  p.org_x[i] = r.o.x; p.org_y[i] = r.o.y; p.org_z[i] = r.o.z;
  p.dir_x[i] = r.d.x; p.dir_y[i] = r.d.y; p.dir_z[i] = r.d.z;
  p.tnear[i] = 0.0f;
  p.tfar[i] = tfar;
  p.time[i] = 0.0f;
  p.mask[i] = 0xFFFFFFFFu;
  p.id[i] = 0;
  p.flags[i] = 0;
}

constexpr float kInfinity = std::numeric_limits<float>::infinity();

}  // namespace pb::cpu
