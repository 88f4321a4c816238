#pragma once
// The scene as flat arrays (host side), plus SceneView: the same arrays as raw
// pointers, valid on the host or (after upload) on the device, which is all the
// shared path step sees.
#include <cstdint>
#include <string>
#include <vector>

#include "pathbench/common/camera.h"
#include "pathbench/common/math.h"
#include "pathbench/common/ray_offset.h"

namespace pb {

enum class MaterialKind : uint32_t { Diffuse = 0 };

struct Material {
  Vec3f albedo;    // two-sided Lambertian reflectance, f = albedo / pi
  Vec3f emission;  // one-sided emitted radiance on the side of the geometric normal
  MaterialKind kind = MaterialKind::Diffuse;
};

struct Triangle {
  uint32_t v[3];
};

// What a scene uses, so tracers carry and branch on nothing else.
struct SceneFeatures {
  uint32_t material_kinds = 0;  // bit i set: MaterialKind(i) present
  bool has_emitters = false;
  float extent = 0;             // bounding-box diagonal, sets ray offsets
  bool uses(MaterialKind k) const { return material_kinds & (1u << uint32_t(k)); }
};

// Plain pointers into the scene's arrays: what kernels and the path step read.
struct SceneView {
  const Vec3f* positions;
  const Triangle* triangles;
  const uint32_t* material_ids;  // per triangle
  const Material* materials;
  const uint32_t* emitters;      // triangle ids of emissive triangles
  const float* emitter_cdf;      // inclusive CDF over emitters, by emitted power
  uint32_t num_triangles;
  uint32_t num_emitters;
  float emitter_power_total;     // sum over emitters of area * mean(emission)
  Camera camera;
  RayOffset offset;

  PB_HD const Material& material_of(uint32_t tri) const { return materials[material_ids[tri]]; }
};

struct Scene {
  std::string name;    // built-in name or file path
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<uint32_t> material_ids;
  std::vector<Material> materials;
  std::vector<std::string> material_names;
  Camera camera{};

  // Derived by finalize().
  std::vector<uint32_t> emitters;
  std::vector<float> emitter_cdf;
  float emitter_power_total = 0;
  Vec3f bounds_min{}, bounds_max{};
  SceneFeatures features;
  RayOffset offset{};
  uint32_t dropped_triangles = 0;

  // Validates (finite coordinates, indices in range, materials sane), drops
  // zero-area triangles with a warning on stderr, and builds the emitter table,
  // bounds, features and ray offsets. Throws InputError naming `name`.
  void finalize();
  SceneView view() const;
  float max_emission() const;
};

}  // namespace pb
