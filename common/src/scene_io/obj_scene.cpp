// Bare OBJ meshes as scenes (with their MTL materials): a camera framing the model and,
// where no material emits, a default area light above it.
#include <fmt/core.h>

#include <cstdio>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"
#include "scene_io/obj_mesh.h"
#include "scenes/builder.h"

namespace pb {

namespace {

// A camera that frames the bounding sphere of [lo, hi], from the front (+z) and a
// little above, as OBJ models are usually modelled with +y up.
Camera framing_camera(Vec3f lo, Vec3f hi) {
  const Vec3f centre = (lo + hi) * 0.5f;
  const float radius = pmax(0.5f * length(hi - lo), 1e-6f);
  const float fov_deg = 40.0f;
  const float distance = 1.05f * radius / std::sin(0.5f * fov_deg * kPi<float> / 180.0f);
  const Vec3f dir = normalize(Vec3f{0, 0.25f, 1});
  return Camera::look_at(centre + dir * distance, centre, {0, 1, 0}, fov_deg);
}

// A quad light above the top of [lo, hi], facing down, overhanging the bounds by a
// quarter of their diagonal on every side (so the sides catch some light too), and
// bright enough that an upward-facing surface of albedo 0.5 below its middle comes
// out at about 0.8.
void add_default_light(Scene& s, Vec3f lo, Vec3f hi) {
  const Vec3f size = hi - lo, centre = (lo + hi) * 0.5f;
  const float diag = pmax(length(size), 1e-6f);
  const float hx = 0.5f * size.x + 0.25f * diag, hz = 0.5f * size.z + 0.25f * diag;
  const float y = hi.y + 0.25f * diag;
  // The irradiance below the middle of the quad at height h is about pi L a^2 / (a^2 +
  // h^2) with a^2 = hx hz; the radiance reflected at albedo 0.5 is half that over pi.
  const float a2 = hx * hz, h = 0.25f * diag;
  const float radiance = 1.6f * (a2 + h * h) / a2;
  const uint32_t light = scenes::add_material(s, "default-light", {0, 0, 0}, {radiance, radiance, radiance});
  using scenes::add_vertex;
  scenes::add_quad(s, add_vertex(s, {centre.x - hx, y, centre.z - hz}), add_vertex(s, {centre.x + hx, y, centre.z - hz}),
                   add_vertex(s, {centre.x + hx, y, centre.z + hz}), add_vertex(s, {centre.x - hx, y, centre.z + hz}),
                   light);
}


}  // namespace

Scene load_scene_obj(const std::string& path) {
  scene_io::ObjMesh mesh = scene_io::read_obj(path, true);
  Scene s;
  s.name = path;
  s.positions = std::move(mesh.positions);
  for (const tinyobj::material_t& m : mesh.materials)
    scenes::add_material(s, m.name, scene_io::clamp01(m.diffuse), {float(m.emission[0]), float(m.emission[1]), float(m.emission[2])});
  uint32_t default_material = ~0u;
  bool has_emitter = false;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    uint32_t mat;
    if (mesh.material_ids[i] >= 0) {
      mat = uint32_t(mesh.material_ids[i]);
    } else {
      if (default_material == ~0u) default_material = scenes::add_material(s, "default", {0.5f, 0.5f, 0.5f});
      mat = default_material;
    }
    has_emitter = has_emitter || max_component(s.materials[mat].emission) > 0;
    const Triangle& t = mesh.triangles[i];
    scenes::add_triangle(s, t.v[0], t.v[1], t.v[2], mat);
  }
  // Bounds of what the faces use (finalize() computes the same later, after the light).
  Vec3f lo = s.positions[s.triangles[0].v[0]], hi = lo;
  for (const Triangle& t : s.triangles)
    for (uint32_t k : t.v) {
      lo = vmin(lo, s.positions[k]);
      hi = vmax(hi, s.positions[k]);
    }
  if (!is_finite(lo) || !is_finite(hi))
    throw InputError(fmt::format("{}: a vertex has a NaN or infinite coordinate", path));
  s.camera = framing_camera(lo, hi);
  if (!has_emitter) {
    add_default_light(s, lo, hi);
    fmt::print(stderr, "note: {}: no emissive material (MTL Ke); added a default area light above the model\n", path);
  }
  s.finalize();
  return s;
}

}  // namespace pb
