#include "pathbench/common/scene_warnings.h"
#include "pathbench/common/scene.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "pathbench/common/errors.h"
#include "pathbench/common/features.h"
#include "pathbench/common/limits.h"

namespace pb {

namespace {
bool finite(Vec3f v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool non_negative(Vec3f v) { return v.x >= 0 && v.y >= 0 && v.z >= 0; }
// Inside the supported coordinate range (limits.h); false for NaN.
bool in_range(Vec3f v) {
  const float m = float(limits::kMaxCoordinate);
  return std::fabs(v.x) <= m && std::fabs(v.y) <= m && std::fabs(v.z) <= m;
}
}  // namespace

const char* to_string(MaterialKind k) {
  switch (k) {
    case MaterialKind::Diffuse: return "diffuse";
    case MaterialKind::Mirror: return "mirror";
    case MaterialKind::Dielectric: return "dielectric";
    case MaterialKind::RoughConductor: return "roughconductor";
  }
  return "unknown";
}

void Scene::finalize() {
  if (triangles.empty()) throw InputError(fmt::format("{}: the scene has no triangles", name));
  if (material_ids.size() != triangles.size())
    throw InputError(fmt::format("{}: {} triangles but {} material ids", name, triangles.size(), material_ids.size()));
  if (materials.empty()) throw InputError(fmt::format("{}: the scene has no materials", name));
  uint64_t instanced = 0;
  for (const SceneInstance& in : instances) instanced += in.triangle_count;
  if (triangles.size() - std::min<uint64_t>(instanced, triangles.size()) > limits::kMaxTriangles)
    throw InputError(fmt::format("{}: {} triangles; the supported maximum is {}", name, triangles.size(),
                                 limits::kMaxTriangles));
  if (triangles.size() > limits::kMaxInstancedTriangles)
    throw InputError(fmt::format("{}: {} triangles with its instances expanded; the supported maximum is {}", name,
                                 triangles.size(), limits::kMaxInstancedTriangles));
  for (size_t i = 0; i < positions.size(); ++i) {
    if (!finite(positions[i]))
      throw InputError(fmt::format("{}: vertex {} has a NaN or infinite coordinate ({}, {}, {})", name, i,
                                   positions[i].x, positions[i].y, positions[i].z));
    if (!in_range(positions[i]))
      throw InputError(fmt::format("{}: vertex {} ({:g}, {:g}, {:g}) is outside the supported coordinate range "
                                   "+-{:g} (after any transform)", name, i, positions[i].x, positions[i].y,
                                   positions[i].z, limits::kMaxCoordinate));
  }
  for (size_t i = 0; i < materials.size(); ++i) {
    const Material& m = materials[i];
    std::string mname = i < material_names.size() ? material_names[i] : std::to_string(i);
    if (!finite(m.albedo) || !non_negative(m.albedo))
      throw InputError(fmt::format("{}: material '{}' has an albedo that is negative, NaN or infinite", name, mname));
    if (m.albedo.x > 1 || m.albedo.y > 1 || m.albedo.z > 1)
      throw InputError(fmt::format("{}: material '{}' has an albedo above 1 (it would create energy)", name, mname));
    if (!finite(m.emission) || !non_negative(m.emission))
      throw InputError(fmt::format("{}: material '{}' has an emission that is negative, NaN or infinite", name, mname));
    if (max_component(m.emission) > float(limits::kMaxEmission))
      throw InputError(fmt::format("{}: material '{}' has emission {:g}, above the supported maximum {:g} (the "
                                   "film's fixed-point sums and float samples cannot represent it)",
                                   name, mname, max_component(m.emission), limits::kMaxEmission));
    if (uint32_t(m.kind) >= kMaterialKindCount)
      throw InputError(fmt::format("{}: material '{}' has an unknown kind {}", name, mname, uint32_t(m.kind)));
    if (m.kind == MaterialKind::Dielectric && !(m.ior > 0 && std::isfinite(m.ior)))
      throw InputError(fmt::format("{}: material '{}': ior {} must be a finite number above 0", name, mname, m.ior));
    if (m.kind == MaterialKind::RoughConductor && !(m.alpha >= Material::kMinAlpha && m.alpha <= 1))
      throw InputError(fmt::format("{}: material '{}': alpha {} is out of range ({} to 1; use a mirror for a smooth one)",
                                   name, mname, m.alpha, Material::kMinAlpha));
  }
  if (!finite(camera.position) || !finite(camera.forward) || !finite(camera.up) || !finite(camera.right) ||
      !(camera.tan_half_fov_y > 0) || !std::isfinite(camera.tan_half_fov_y))
    throw InputError(fmt::format("{}: the camera is degenerate (NaN, zero direction or field of view)", name));
  if (!in_range(camera.position))
    throw InputError(fmt::format("{}: the camera position ({:g}, {:g}, {:g}) is outside the supported coordinate "
                                 "range +-{:g}", name, camera.position.x, camera.position.y, camera.position.z,
                                 limits::kMaxCoordinate));

  // Indices in range; zero-area triangles dropped (they can never be hit, and they
  // would give NaN normals).
  std::vector<Triangle> kept;
  std::vector<uint32_t> kept_mat;
  kept.reserve(triangles.size());
  kept_mat.reserve(triangles.size());
  dropped_triangles = 0;
  std::vector<uint32_t> kept_before(instances.empty() ? 0 : triangles.size() + 1, 0);
  for (size_t i = 0; i < triangles.size(); ++i) {
    if (!kept_before.empty()) kept_before[i] = uint32_t(kept.size());
    const Triangle& t = triangles[i];
    for (uint32_t k : t.v)
      if (k >= positions.size())
        throw InputError(fmt::format("{}: triangle {} refers to vertex {}, but there are only {} vertices", name, i,
                                     k, positions.size()));
    if (material_ids[i] >= materials.size())
      throw InputError(fmt::format("{}: triangle {} refers to material {}, but there are only {} materials", name, i,
                                   material_ids[i], materials.size()));
    Vec3f e1 = positions[t.v[1]] - positions[t.v[0]];
    Vec3f e2 = positions[t.v[2]] - positions[t.v[0]];
    Vec3f c = cross(e1, e2);
    float area2 = length(c);
    // Edges inside the range whose cross product overflows float: the normal cannot be
    // computed. Not a zero-area triangle, so not dropped silently.
    if (finite(c) && std::isinf(area2))
      throw InputError(fmt::format("{}: triangle {} is too large for float arithmetic (its normal overflows: keep "
                                   "triangle edges below about 1e9)", name, i));
    if (!(area2 > 0) || !std::isfinite(area2) || !finite(normalize(c))) {
      ++dropped_triangles;
      continue;
    }
    kept.push_back(t);
    kept_mat.push_back(material_ids[i]);
  }
  if (!kept_before.empty()) kept_before[triangles.size()] = uint32_t(kept.size());
  if (dropped_triangles && !instances.empty()) {
    // Instance ranges follow the triangles that were kept: kept_before[i] counts the
    // kept triangles with index below i.
    for (SceneInstance& in : instances) {
      const uint32_t end = in.first_triangle + in.triangle_count;
      in.first_triangle = kept_before[in.first_triangle];
      in.triangle_count = kept_before[end] - in.first_triangle;
    }
  }
  instanced_triangle_count = 0;  // also right for instances a caller pushed itself
  for (const SceneInstance& in : instances) instanced_triangle_count += in.triangle_count;
  if (dropped_triangles)
    scene_warning(fmt::format("{}: dropped {} zero-area triangle{}", name, dropped_triangles,
                              dropped_triangles == 1 ? "" : "s"));
  if (kept.empty()) throw InputError(fmt::format("{}: every triangle has zero area", name));
  triangles = std::move(kept);
  material_ids = std::move(kept_mat);

  // Bounds and the offsets that follow the scene's scale.
  bounds_min = bounds_max = positions[triangles[0].v[0]];
  for (const Triangle& t : triangles)
    for (uint32_t k : t.v) {
      bounds_min = vmin(bounds_min, positions[k]);
      bounds_max = vmax(bounds_max, positions[k]);
    }
  features = {};
  features.extent = length(bounds_max - bounds_min);
  rebase_far_from_origin();  // scene_origin.cpp; the extent does not change
  offset = RayOffset::for_extent(features.extent);

  // Emitters, chosen in proportion to their power (area x mean emission).
  emitters.clear();
  emitter_cdf.clear();
  double total = 0;
  std::vector<double> power;
  for (uint32_t i = 0; i < triangles.size(); ++i) {
    const Material& m = materials[material_ids[i]];
    features.material_kinds |= 1u << uint32_t(m.kind);
    double mean = (double(m.emission.x) + m.emission.y + m.emission.z) / 3.0;
    if (mean <= 0) continue;
    const Triangle& t = triangles[i];
    double area = 0.5 * length(cross(positions[t.v[1]] - positions[t.v[0]], positions[t.v[2]] - positions[t.v[0]]));
    emitters.push_back(i);
    power.push_back(area * mean);
    total += area * mean;
  }
  double acc = 0;
  for (double p : power) {
    acc += p;
    emitter_cdf.push_back(float(acc / total));
  }
  if (!emitter_cdf.empty()) emitter_cdf.back() = 1.0f;
  emitter_power_total = float(total);
  if (!std::isfinite(emitter_power_total))
    throw InputError(fmt::format("{}: the emitters' total power (area x emission, {:g}) overflows float; make the "
                                 "lights smaller or dimmer", name, total));
  features.has_emitters = !emitters.empty();
  if (const uint32_t missing = features.material_kinds & ~kCompiledMaterialKinds) {
    std::string kinds;
    for (uint32_t k = 0; k < kMaterialKindCount; ++k)
      if (missing & (1u << k)) kinds += (kinds.empty() ? "" : ", ") + std::string(to_string(MaterialKind(k)));
    throw InputError(fmt::format("{}: uses material kind(s) {}, but this build has only diffuse materials "
                                 "(configured with -DPATHBENCH_EXTRA_MATERIALS=OFF)", name, kinds));
  }
}

SceneView Scene::view() const {
  return {positions.data(), triangles.data(),  material_ids.data(),        materials.data(),
          emitters.data(),  emitter_cdf.data(), uint32_t(triangles.size()), uint32_t(emitters.size()),
          emitter_power_total, camera,          offset,   features.material_kinds};
}

float Scene::max_emission() const {
  float m = 0;
  for (const Material& mat : materials) m = pmax(m, max_component(mat.emission));
  return m;
}

}  // namespace pb
