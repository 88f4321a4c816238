#pragma once
// Scale-aware ray origin offset (after Waechter & Binder, "A Fast and Robust Method
// for Avoiding Self-Intersection", Ray Tracing Gems, 2019). Far from the origin the
// point moves a fixed number of float ulps along the normal (relative error); near the
// origin, where ulps vanish but the error of the computed point does not, it moves by a
// fixed distance. Unlike the paper's constants (1/32 and 1/65536, right for unit-sized
// scenes), both thresholds follow the scene's extent, so a scene scaled by 1e-4 or 1e5
// is offset the same way relative to its size.
#include <cstdint>
#include <cstring>

#include "pathbench/common/math.h"

namespace pb {

struct RayOffset {
  float near_origin;      // below this |coordinate|, use the fixed distance
  float fixed_distance;   // offset distance near the origin
  static RayOffset for_extent(float extent) {
    float e = extent > 0 ? extent : 1.0f;
    return {e * (1.0f / 32.0f), e * (1.0f / 65536.0f)};
  }
};

// Moves p off the surface along n (the side the new ray leaves from). The offset is
// always computed on the float grid, the precision the intersector works in.
template <class T> PB_HD Vec3<T> offset_ray_origin(Vec3<T> p, Vec3<T> n, const RayOffset& off) {
  constexpr float kIntScale = 256.0f;
  Vec3<T> r;
  for (int i = 0; i < 3; ++i) {
    float pc = float(p[i]);
    float nc = float(n[i]);
    float moved;
    if (std::fabs(pc) < off.near_origin) {
      moved = fmadd(off.fixed_distance, nc, pc);
    } else {
      int32_t of = int32_t(kIntScale * nc);
      int32_t bits;
      std::memcpy(&bits, &pc, sizeof bits);
      bits += (pc < 0) ? -of : of;
      std::memcpy(&moved, &bits, sizeof moved);
    }
    r[i] = T(moved);
  }
  return r;
}

}  // namespace pb
