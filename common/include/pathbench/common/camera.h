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
  // The image plane at distance 1: x from -tan_x (left) to +tan_x, y from +tan_y (top)
  // to -tan_y; square pixels, each `step` wide. One division per ray where there were
  // two (the CPU's batched twin, cpu/src/shade_x8.h's begin_paths, computes the same).
  const T tan_y = T(c.tan_half_fov_y);
  const T tan_x = tan_y * T(width) / T(height);
  const T step = T(2) * tan_y / T(height);
  const T x = fmadd(T(px) + T(jx), step, -tan_x);
  const T y = fmadd(-(T(py) + T(jy)), step, tan_y);
  const Vec3<T> d = fmadd(Vec3<T>(c.up), y, fmadd(Vec3<T>(c.right), x, Vec3<T>(c.forward)));
  return {Vec3<T>(c.position), fnormalize(d)};
}

}  // namespace pb
