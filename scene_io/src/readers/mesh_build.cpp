// Shared by the scene-file readers: reporting what is not modelled, reading a mesh file
// by its extension, placing meshes (flattened, with instancing kept), and framing a
// bare mesh with a camera and a default light.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "pathbench/common/scene_warnings.h"
#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/limits.h"
#include "readers/readers.h"
#include "scenes/builder.h"

namespace pb::scene_io {

namespace fs = std::filesystem;

void Losses::report(const std::string& path, const std::string& what) const {
  if (strict_) throw InputError(fmt::format("{}: {}: not modelled by pathbench (--strict)", path, what));
  if (said_.insert(what).second) scene_warning(fmt::format("{}: {} (not modelled; ignored)", path, what));
}

FileReader disk_reader() {
  return {[](const std::string& path, const char* what, uint64_t max_bytes) {
            return read_input_file(path, what, max_bytes);
          },
          // With an error code: a symlink loop or a long name is read_input_file's to report.
          [](const std::string& path) {
            std::error_code ec;
            return fs::exists(path, ec) || ec;
          }};
}

MeshData read_mesh_file(const std::string& path, bool with_materials, const FileReader& read, const Losses& losses,
                        uint64_t& budget) {
  const std::string ext = image_extension(path);  // lower case
  if (ext != ".obj" && ext != ".ply" && ext != ".off")
    throw InputError(fmt::format("{}: unsupported mesh file type '{}' (expected .obj, .ply or .off)", path, ext));
  const char* what = ext == ".ply" ? "mesh file (PLY)" : ext == ".off" ? "mesh file (OFF)" : "mesh file (OBJ)";
  const std::string text = read.read(path, what, limits::kMaxMeshBytes);
  budget += text.size();
  if (budget > limits::kMaxMeshBytes)
    throw InputError(fmt::format("{}: the mesh files (OBJ, PLY, OFF) of one scene are limited to {} in all", path,
                                 format_bytes(limits::kMaxMeshBytes)));
  if (ext == ".ply") return read_ply(path, text, losses);
  if (ext == ".off") return read_off(path, text, losses);
  return read_obj_mesh(path, text, with_materials, read, losses);
}

uint64_t instanced_triangles(const Scene& s) { return s.instanced_triangle_count; }

namespace {

// Room for `more` elements, growing geometrically: reserving exactly size() + more
// for each placed mesh reallocates (copies the scene) on every placement, which made
// loading quadratic in the placements (issue 34: 4,096 Mitsuba spheres took > 30 s).
template <class T> void reserve_more(std::vector<T>& v, size_t more) {
  if (v.capacity() - v.size() < more) v.reserve(std::max(v.size() + more, 2 * v.capacity()));
}

// `instanced`: the geometry is one placement of a prototype. Triangles outside instances stay
// under kMaxTriangles (in a scene without instances, its vertices under kMaxVertices); with
// the instances expanded the scene may hold up to kMaxInstancedTriangles (and three vertices
// a triangle).
uint32_t append_geometry(Scene& s, const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles,
                         const Affine& to_world, const std::vector<uint32_t>& materials, bool flip_winding,
                         bool instanced) {
  if (s.triangles.size() + triangles.size() > limits::kMaxInstancedTriangles)
    throw InputError(fmt::format("{}: the scene has more than {} triangles with its instances expanded (the "
                                 "supported maximum)", s.name, limits::kMaxInstancedTriangles));
  if (s.positions.size() + positions.size() > 3 * limits::kMaxInstancedTriangles)
    throw InputError(fmt::format("{}: the scene has more than {} vertices with its instances expanded (the "
                                 "supported maximum)", s.name, 3 * limits::kMaxInstancedTriangles));
  if (!instanced) {
    const uint64_t flat = s.triangles.size() - instanced_triangles(s);
    if (flat + triangles.size() > limits::kMaxTriangles)
      throw InputError(fmt::format("{}: the scene has more than {} triangles (the supported maximum)", s.name,
                                   limits::kMaxTriangles));
    if (s.positions.size() + positions.size() > limits::kMaxVertices && s.instances.empty())
      throw InputError(fmt::format("{}: the scene has more than {} vertices (the supported maximum)", s.name,
                                   limits::kMaxVertices));
  }
  const uint32_t base = uint32_t(s.positions.size()), first = uint32_t(s.triangles.size());
  reserve_more(s.positions, positions.size());
  reserve_more(s.triangles, triangles.size());
  reserve_more(s.material_ids, triangles.size());
  for (const Vec3f& p : positions) s.positions.push_back(to_world.point(p));
  for (size_t i = 0; i < triangles.size(); ++i) {
    const Triangle& t = triangles[i];
    const uint32_t mat = materials.size() == 1 ? materials[0] : materials.at(i);
    if (flip_winding)
      scenes::add_triangle(s, base + t.v[0], base + t.v[2], base + t.v[1], mat);
    else
      scenes::add_triangle(s, base + t.v[0], base + t.v[1], base + t.v[2], mat);
  }
  return first;
}

}  // namespace

uint32_t append_mesh(Scene& s, const MeshData& mesh, const Affine& to_world, const std::vector<uint32_t>& materials,
                     bool flip_winding) {
  return append_geometry(s, mesh.positions, mesh.triangles, to_world, materials, flip_winding, false);
}

uint32_t add_prototype(Scene& s, std::string name, const MeshData& mesh, const std::vector<uint32_t>& materials) {
  ScenePrototype p{std::move(name), mesh.positions, mesh.triangles, {}};
  p.material_ids.reserve(mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i)
    p.material_ids.push_back(materials.size() == 1 ? materials[0] : materials.at(i));
  s.prototypes.push_back(std::move(p));
  return uint32_t(s.prototypes.size() - 1);
}

void add_instance(Scene& s, uint32_t prototype, const Affine& to_world, bool flip_winding) {
  if (s.instances.size() >= limits::kMaxPlacements)
    throw InputError(fmt::format("{}: more than {} placed instances (the supported maximum)", s.name,
                                 limits::kMaxPlacements));
  const ScenePrototype& p = s.prototypes.at(prototype);
  // The prototype's own arrays, not a copy per placement.
  const uint32_t first = append_geometry(s, p.positions, p.triangles, to_world, p.material_ids, flip_winding, true);
  s.instances.push_back({prototype, to_world, first, uint32_t(p.triangles.size())});
  s.instanced_triangle_count += p.triangles.size();
}

namespace {

// A camera that frames the bounding sphere of [lo, hi], from the front (+z) and a
// little above, as models are usually modelled with +y up.
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

void frame_bare_mesh(Scene& s, const std::string& path, bool set_camera, const char* emitter_hint) {
  if (s.triangles.empty()) throw InputError(fmt::format("{}: the file has no faces", path));
  bool has_emitter = false;
  for (uint32_t m : s.material_ids) has_emitter = has_emitter || max_component(s.materials[m].emission) > 0;
  // Bounds of what the faces use (finalize() computes the same later, after the light).
  Vec3f lo = s.positions[s.triangles[0].v[0]], hi = lo;
  for (const Triangle& t : s.triangles)
    for (uint32_t k : t.v) {
      lo = vmin(lo, s.positions[k]);
      hi = vmax(hi, s.positions[k]);
    }
  if (!is_finite(lo) || !is_finite(hi))
    throw InputError(fmt::format("{}: a vertex has a NaN or infinite coordinate", path));
  // The camera and the default light sit a few model sizes away from the model, so a
  // framed model must lie well inside the supported range (its 1/8).
  const double reach = limits::kMaxCoordinate / 8;
  if (std::max(max_component(vmax(hi, -lo)), 0.0f) > reach)
    throw InputError(fmt::format("{}: the model reaches {:g}; a bare mesh is framed automatically, so its "
                                 "coordinates must lie within +-{:g} (1/8 of the supported range +-{:g})",
                                 path, double(max_component(vmax(hi, -lo))), reach, limits::kMaxCoordinate));
  if (set_camera) s.camera = framing_camera(lo, hi);
  if (!has_emitter) {
    add_default_light(s, lo, hi);
    scene_note(fmt::format("{}: no emissive material ({}); added a default area light above the model", path,
                           emitter_hint));
  }
}

Scene bare_mesh_scene(const std::string& path, const MeshData& mesh, const char* emitter_hint) {
  Scene s;
  s.name = path;
  const uint32_t grey = scenes::add_material(s, "default", {0.5f, 0.5f, 0.5f});
  append_mesh(s, mesh, Affine(), {grey});
  frame_bare_mesh(s, path, true, emitter_hint);
  return s;
}

}  // namespace pb::scene_io
