#pragma once
// The scene as flat arrays (host side), plus SceneView: the same arrays as raw
// pointers, valid on the host or (after upload) on the device, which is all the
// shared path step sees.
#include <cstdint>
#include <string>
#include <vector>

#include "pathbench/common/affine.h"
#include "pathbench/common/camera.h"
#include "pathbench/common/math.h"
#include "pathbench/common/ray_offset.h"

namespace pb {

// The BSDFs (one header each under bsdf/, named after Mitsuba 3's plugins they match).
enum class MaterialKind : uint32_t {
  Diffuse = 0,         // two-sided Lambertian (bsdf/lambert.h)
  Mirror = 1,          // perfect mirror (bsdf/mirror.h)
  Dielectric = 2,      // smooth glass (bsdf/dielectric.h)
  RoughConductor = 3,  // GGX microfacet metal (bsdf/roughconductor.h)
};
constexpr uint32_t kMaterialKindCount = 4;
const char* to_string(MaterialKind k);  // "diffuse", "mirror", "dielectric", "roughconductor"

struct Material {
  Vec3f albedo;    // diffuse: reflectance, f = albedo / pi; mirror and rough conductor:
                   // specular reflectance; dielectric: tint of reflection and transmission
  Vec3f emission;  // one-sided emitted radiance on the side of the geometric normal
  MaterialKind kind = MaterialKind::Diffuse;
  float ior = 1.5f;    // dielectric: interior index of refraction (exterior 1), > 0
  float alpha = 0.1f;  // rough conductor: GGX roughness alpha, in [kMinAlpha, 1]
  static constexpr float kMinAlpha = 1e-3f;  // below, float GGX is a mirror with NaNs
};

struct Triangle {
  uint32_t v[3];
};

// What a scene uses, so tracers carry and branch on nothing else.
struct SceneFeatures {
  uint32_t material_kinds = 0;  // bit i set: MaterialKind(i) present (features.h dispatches on it)
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
  uint32_t material_kinds;       // SceneFeatures::material_kinds: picks the path step's instantiation

  PB_HD const Material& material_of(uint32_t tri) const { return materials[material_ids[tri]]; }
};

// Instancing as a scene file describes it (JSON "instances", Mitsuba shapegroup and
// instance, a glTF mesh used by several nodes). Loading expands every instance into the
// flat arrays (the tracers see triangles only); this record is kept so that a tracer
// can build Embree instances or a two-level BVH from it instead.
struct ScenePrototype {
  std::string name;
  std::vector<Vec3f> positions;  // the prototype's own coordinates
  std::vector<Triangle> triangles;
  std::vector<uint32_t> material_ids;
};
struct SceneInstance {
  uint32_t prototype;        // index into Scene::prototypes
  Affine to_world;           // prototype coordinates -> user coordinates
  uint32_t first_triangle;   // where its expansion sits in Scene::triangles (after finalize)
  uint32_t triangle_count;   // its triangles kept there (finalize drops zero-area ones)
};

// What a scene file asks of the render (Mitsuba's film, sampler and integrator): the
// render command uses each unless its option is given. 0 / kUnset: the file says nothing.
struct SceneRenderDefaults {
  static constexpr int kUnset = -2;
  uint32_t width = 0, height = 0, spp = 0;
  int max_bounces = kUnset;  // -1: unbounded (Mitsuba max_depth -1)
};

struct Scene {
  std::string name;    // built-in name or file path
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<uint32_t> material_ids;
  std::vector<Material> materials;
  std::vector<std::string> material_names;
  Camera camera{};
  std::vector<ScenePrototype> prototypes;
  std::vector<SceneInstance> instances;
  // The sum of the instances' triangle_count, kept as they are placed (scene_io::add_instance)
  // and by finalize(): the readers check the flat-triangle limit on every mesh they append,
  // and summing the instances each time made loading quadratic.
  uint64_t instanced_triangle_count = 0;
  SceneRenderDefaults render_defaults;

  // Derived by finalize().
  std::vector<uint32_t> emitters;
  std::vector<float> emitter_cdf;
  float emitter_power_total = 0;
  Vec3f bounds_min{}, bounds_max{};
  SceneFeatures features;
  RayOffset offset{};
  uint32_t dropped_triangles = 0;
  // Where the traced coordinates sit in the user's: user = positions + origin (the camera
  // and bounds too). Zero unless finalize() moved a scene lying far from the origin next
  // to it (scene_origin.cpp); what a user reads back (Python's positions, bounds, rays)
  // adds it back. The tracers never see it.
  Vec3f origin{0, 0, 0};
  // Below this many float32 steps (at its largest coordinate) across its extent, a
  // scene's input was rounded visibly: finalize() warns.
  static constexpr double kMinFloatStepsAcross = 4096;

  // Validates (finite coordinates, indices in range, materials sane), drops
  // zero-area triangles with a warning on stderr, and builds the emitter table,
  // bounds, features and ray offsets; a scene far from the origin is moved next to it
  // (origin). Throws InputError naming `name`.
  void finalize();
  SceneView view() const;
  float max_emission() const;

 private:
  void rebase_far_from_origin();  // part of finalize()
};

// An instance's prototype coordinates -> the traced ones (to_world less Scene::origin).
Affine traced_to_world(const Scene& s, const SceneInstance& in);
// The largest difference (max norm, traced units) between a vertex of the instance's flat
// triangles and the matching prototype vertex under traced_to_world, in double: the
// rounding its expansion went through (half an ulp; more where the scene was rebased far
// from the origin or rescaled). Infinity where the instance lost triangles to finalize().
double instance_deviation(const Scene& s, const SceneInstance& in);

// The scene with every point p (user coordinates) moved to p * scale + offset, the
// camera too, then finalized again (bounds, offsets and origin follow). Throws
// InputError for a scale that is not finite and positive or an offset that is not finite.
Scene transformed(Scene s, float scale, Vec3f offset);

}  // namespace pb
