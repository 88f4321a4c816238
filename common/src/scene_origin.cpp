// Scenes far from the origin (issue 18). The tracers work in float32, where a
// coordinate near 1e4 has steps of 1e-3 and near 1e5 of 8e-3: every ray origin offset,
// hit point and light sample far from the origin is as coarse as that, however small
// the scene. So finalize() moves a scene that lies far from the origin next to it,
// once, exactly (a translation subtracted from every vertex and the camera), and keeps
// the translation in Scene::origin: user coordinates = traced coordinates + origin.
// Radiance does not depend on position, so the image is that of the scene near the
// origin. What no rebasing can undo is the rounding of the input itself (a vertex given
// at 1e5 + 9.9 was already rounded by up to 4e-3 when it became a float): when that
// rounding is a sizeable part of the scene's extent, finalize() warns.
#include <fmt/core.h>

#include <cmath>

#include "pathbench/common/scene_warnings.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/scene.h"

namespace pb {

namespace {

// Float spacing (one ulp) at magnitude x >= 0: 2^(exponent of x - 23).
double float_step(double x) {
  if (!(x > 0)) return std::ldexp(1.0, -149);
  int e = 0;
  std::frexp(x, &e);  // x = f 2^e, f in [0.5, 1)
  return std::ldexp(1.0, e - 24);
}

}  // namespace

// Per axis, a scene whose centre m lies more than twice its extent from the origin (so
// every coordinate p on that axis has the sign of m and |p| > 1.5 extents) is moved by
// c = m rounded to a multiple of the float step U of the axis's largest coordinate.
// Each p is a multiple of its own step (a power of two <= U, so c is a multiple of it
// too), and |p - c| <= extent / 2 + U / 2 < |p|, so p - c is a float: the subtraction is
// exact, and traced + origin gives back the very floats
// the scene was given. Scenes near the origin (every built-in, every test scene that is
// not moved on purpose) are left alone: their images and reports do not change.
void Scene::rebase_far_from_origin() {
  const Vec3d lo(bounds_min), hi(bounds_max);
  const double extent = length(hi - lo);
  Vec3f shift{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const double m = 0.5 * (lo[k] + hi[k]);
    if (!(std::fabs(m) > 2 * extent)) continue;
    const double step = float_step(std::fmax(std::fabs(lo[k]), std::fabs(hi[k])));
    shift[k] = float(std::nearbyint(m / step) * step);
  }
  if (!is_zero(shift)) {
    for (Vec3f& p : positions) p = p - shift;
    camera.position = camera.position - shift;  // rounds only where the camera is far from the scene
    bounds_min = bounds_min - shift;
    bounds_max = bounds_max - shift;
    origin = origin + shift;
  }

  // The rounding the input went through: half a float step at the largest user
  // coordinate, against the scene's extent.
  const Vec3d user_lo = Vec3d(bounds_min) + Vec3d(origin), user_hi = Vec3d(bounds_max) + Vec3d(origin);
  const double largest = max_component(vmax(vabs(user_lo), vabs(user_hi)));
  const double steps = extent / float_step(largest);
  if (extent > 0 && steps < kMinFloatStepsAcross)
    scene_warning(fmt::format(
               "{}: the scene is {:.3g} units across but lies {:.3g} units from the origin: float32 "
               "coordinates there have steps of {:.3g}, only {:.0f} across the scene, so its vertices were "
               "rounded by up to 1/{:.0f} of its size when they were read. The image may differ from the same "
               "scene near the origin (unchanged up to {:.0f} steps across); move the scene's coordinates "
               "closer to the origin.",
               name, extent, largest, float_step(largest), steps, 2 * steps, kMinFloatStepsAcross));
}

Scene transformed(Scene s, float scale, Vec3f offset) {
  if (!(std::isfinite(scale) && scale > 0.0f))
    throw InputError(fmt::format("scale must be finite and positive, got {}", scale));
  if (!(std::isfinite(offset.x) && std::isfinite(offset.y) && std::isfinite(offset.z)))
    throw InputError(fmt::format("offset must be finite, got ({}, {}, {})", offset.x, offset.y, offset.z));
  if (scale == 1.0f && offset.x == 0.0f && offset.y == 0.0f && offset.z == 0.0f) return s;
  // In the user's coordinates (traced + origin is exact, see above), then rebased anew.
  for (Vec3f& p : s.positions) p = (p + s.origin) * scale + offset;
  s.camera.position = (s.camera.position + s.origin) * scale + offset;
  for (SceneInstance& in : s.instances)
    in.to_world = Affine::translate(offset.x, offset.y, offset.z) * Affine::scale(scale, scale, scale) * in.to_world;
  s.origin = {0, 0, 0};
  s.finalize();
  return s;
}

}  // namespace pb
