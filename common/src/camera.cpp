#include "pathbench/common/camera.h"

namespace pb {

Camera Camera::look_at(Vec3f eye, Vec3f target, Vec3f up_hint, float fov_y_deg) {
  Camera c;
  c.position = eye;
  c.forward = normalize(target - eye);
  c.right = normalize(cross(c.forward, up_hint));
  c.up = cross(c.right, c.forward);
  c.tan_half_fov_y = std::tan(fov_y_deg * 0.5f * kPi<float> / 180.0f);
  return c;
}

}  // namespace pb
