#pragma once
// Pinhole camera with a box pixel filter: rays jittered uniformly inside the pixel.
// Row 0 is the top of the image, column 0 the left.
#include <cstdint>

#include "pathbench/common/math.h"

namespace pb {

struct Camera {
  Vec3f position;
  Vec3f forward, right, up;  // orthonormal
  float tan_half_fov_y;       // the horizontal one follows the image's aspect ratio

  // Looking from `eye` towards `target`; `fov_y_deg` is the full vertical field of view.
  static Camera look_at(Vec3f eye, Vec3f target, Vec3f up_hint, float fov_y_deg);
};

template <class T> struct Ray {
  Vec3<T> o, d;
};

template <class T>
PB_HD Ray<T> camera_ray(const Camera& c, uint32_t px, uint32_t py, uint32_t width, uint32_t height, float jx,
                        float jy) {
  T sx = (T(px) + T(jx)) / T(width) * T(2) - T(1);   // -1 left .. +1 right
  T sy = T(1) - (T(py) + T(jy)) / T(height) * T(2);  // +1 top .. -1 bottom
  T tan_y = T(c.tan_half_fov_y);
  T tan_x = tan_y * T(width) / T(height);
  Vec3<T> d = Vec3<T>(c.forward) + Vec3<T>(c.right) * (sx * tan_x) + Vec3<T>(c.up) * (sy * tan_y);
  return {Vec3<T>(c.position), normalize(d)};
}

}  // namespace pb
