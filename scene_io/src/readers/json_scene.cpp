// JSON scene descriptions (scenes/README.md gives the format); the OBJ meshes they name
// are read by obj_scene.cpp. Every problem with a file is one InputError naming the file
// and, where there is one, the JSON field.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <unordered_map>

#include "pathbench/common/scene_warnings.h"
#include "pathbench/scene_io/data_dir.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/json_input.h"
#include "pathbench/common/limits.h"
#include "pathbench/scene_io/scene_library.h"
#include "readers/readers.h"
#include "scenes/builder.h"

namespace pb::scene_io {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------
// JSON.

using Json = nlohmann::ordered_json;  // keeps the materials in file order

class JsonSceneReader {
 public:
  JsonSceneReader(std::string path, const FileReader& read, const Losses& losses)
      : path_(std::move(path)), read_(read), losses_(losses) {}

  Scene read(const std::string& text) {
    Json root;
    try {
      root = parse_json_bounded<Json>(text, path_);
    } catch (const Json::exception& e) {
      // "[json.exception.parse_error.101] parse error at line 3, column 1: ..." without the
      // tag; also out_of_range.406, "number overflow parsing '1e999'".
      std::string what = e.what();
      if (const size_t tag = what.find("] "); what.rfind("[json.exception", 0) == 0 && tag != std::string::npos)
        what = what.substr(tag + 2);
      throw InputError(fmt::format("{}: malformed JSON: {}", path_, what));
    }
    if (!root.is_object()) fail("", "expected a JSON object at the top, got " + got(root));
    allow_keys(root, "", {"description", "camera", "materials", "meshes", "triangles"});

    Scene s;
    s.name = path_;
    read_camera(s, member(root, "camera", ""));
    // Optional when every mesh brings its own (MTL) materials.
    const Json& materials = root.contains("materials") ? root["materials"] : Json::object();
    if (!materials.is_object())
      fail("materials", "expected an object of named materials, e.g. {\"white\": {\"albedo\": [0.5, 0.5, 0.5]}}");
    for (const auto& [name, m] : materials.items()) scenes::append_material(s, name, read_material(m, "materials." + name));
    if (root.contains("meshes")) {
      const Json& meshes = array(root["meshes"], "meshes");
      for (size_t i = 0; i < meshes.size(); ++i) read_mesh(s, meshes[i], fmt::format("meshes[{}]", i));
    }
    if (root.contains("triangles")) {
      const Json& groups = array(root["triangles"], "triangles");
      for (size_t i = 0; i < groups.size(); ++i) read_triangles(s, groups[i], fmt::format("triangles[{}]", i));
    }
    if (s.triangles.empty()) fail("", "the scene has no triangles (give \"meshes\" or \"triangles\")");
    return s;
  }

 private:
  std::string path_;
  const FileReader& read_;
  const Losses& losses_;
  mutable uint64_t mesh_bytes_ = 0;  // all mesh files read so far: one budget for the scene
  mutable std::unordered_map<std::string, uint32_t> material_index_;  // name -> first material of that name
  mutable size_t indexed_ = 0;  // materials in material_index_ (the first ones)

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    if (field.empty()) throw InputError(fmt::format("{}: {}", path_, what));
    throw InputError(fmt::format("{}: {}: {}", path_, field, what));
  }
  static std::string join(const std::string& field, const char* key) {
    return field.empty() ? std::string(key) : field + "." + key;
  }
  const Json& member(const Json& obj, const char* key, const std::string& field) const {
    if (!obj.contains(key)) fail(join(field, key), "missing");
    return obj[key];
  }
  void allow_keys(const Json& obj, const std::string& field, std::initializer_list<const char*> keys) const {
    for (const auto& item : obj.items()) {
      const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture those
      if (std::none_of(keys.begin(), keys.end(), [&](const char* k) { return key == k; })) {
        std::string allowed;
        for (const char* k : keys) allowed += (allowed.empty() ? "" : ", ") + std::string(k);
        fail(field.empty() ? key : field + "." + key, fmt::format("unknown key (expected one of: {})", allowed));
      }
    }
  }
  // What a value is, for messages: a scalar as written (shortened), a container by kind.
  static std::string got(const Json& j) {
    if (j.is_array()) return fmt::format("an array of {} element{}", j.size(), j.size() == 1 ? "" : "s");
    if (j.is_object()) return "an object";
    std::string text = j.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return fmt::format("{} {}", j.type_name(), text);
  }
  const Json& array(const Json& j, const std::string& field) const {
    if (!j.is_array()) fail(field, "expected an array, got " + got(j));
    return j;
  }
  const Json& object(const Json& j, const std::string& field) const {
    if (!j.is_object()) fail(field, "expected an object, got " + got(j));
    return j;
  }
  float number(const Json& j, const std::string& field) const {
    if (!j.is_number()) fail(field, "expected a number, got " + got(j));
    const double v = j.get<double>();
    if (!std::isfinite(float(v))) fail(field, fmt::format("{} is not a finite number (or too large for a float)", v));
    return float(v);
  }
  Vec3f vec3(const Json& j, const std::string& field) const {
    if (!j.is_array() || j.size() != 3) fail(field, "expected an array of 3 numbers, got " + got(j));
    return {number(j[0], field + "[0]"), number(j[1], field + "[1]"), number(j[2], field + "[2]")};
  }
  std::string string(const Json& j, const std::string& field) const {
    if (!j.is_string()) fail(field, "expected a string, got " + got(j));
    return j.get<std::string>();
  }
  uint32_t material(const Scene& s, const Json& j, const std::string& field) const {
    const std::string name = string(j, field);
    // A map, not a search per use: many groups times many materials stays linear. It
    // takes in only the materials added since (meshes with their own MTL materials add
    // some between lookups): rebuilding it whole made those scenes quadratic.
    for (; indexed_ < s.material_names.size(); ++indexed_) material_index_.emplace(s.material_names[indexed_], uint32_t(indexed_));
    if (auto it = material_index_.find(name); it != material_index_.end()) return it->second;
    std::string known;
    for (const std::string& n : s.material_names) {
      if (known.size() > 200) {
        known += ", ...";
        break;
      }
      known += (known.empty() ? "" : ", ") + n;
    }
    fail(field, fmt::format("unknown material '{:.80}' (the file defines: {})", name, known));
  }

  // {"kind": K, "albedo": [r, g, b], "emission": [r, g, b], "ior": x, "alpha": x}: kind
  // "diffuse" (the default), "mirror", "dielectric" or "roughconductor"; "ior" only for
  // a dielectric, "alpha" only for a rough conductor. The albedo defaults to black for
  // a diffuse material (an emitter, say) and to white for the others.
  Material read_material(const Json& m, const std::string& field) const {
    object(m, field);
    Material mat;
    if (m.contains("kind")) {
      const std::string kind = string(m["kind"], field + ".kind");
      uint32_t k = 0;
      while (k < kMaterialKindCount && kind != to_string(MaterialKind(k))) ++k;
      if (k == kMaterialKindCount)
        fail(field + ".kind", fmt::format("unknown material kind '{}' (expected one of: diffuse, mirror, dielectric, "
                                          "roughconductor)", kind));
      mat.kind = MaterialKind(k);
    }
    if (m.contains("ior") && mat.kind != MaterialKind::Dielectric)
      fail(field + ".ior", "applies only to materials of kind \"dielectric\"");
    if (m.contains("alpha") && mat.kind != MaterialKind::RoughConductor)
      fail(field + ".alpha", "applies only to materials of kind \"roughconductor\"");
    switch (mat.kind) {
      case MaterialKind::Dielectric: allow_keys(m, field, {"kind", "albedo", "emission", "ior"}); break;
      case MaterialKind::RoughConductor: allow_keys(m, field, {"kind", "albedo", "emission", "alpha"}); break;
      default: allow_keys(m, field, {"kind", "albedo", "emission"}); break;
    }
    const Vec3f default_albedo = mat.kind == MaterialKind::Diffuse ? Vec3f{0, 0, 0} : Vec3f{1, 1, 1};
    mat.albedo = m.contains("albedo") ? vec3(m["albedo"], field + ".albedo") : default_albedo;
    mat.emission = m.contains("emission") ? vec3(m["emission"], field + ".emission") : Vec3f{0, 0, 0};
    if (m.contains("ior")) {
      mat.ior = number(m["ior"], field + ".ior");
      if (!(mat.ior > 0)) fail(field + ".ior", fmt::format("{} is not an index of refraction (must be above 0)", mat.ior));
    }
    if (m.contains("alpha")) {
      mat.alpha = number(m["alpha"], field + ".alpha");
      if (!(mat.alpha >= Material::kMinAlpha && mat.alpha <= 1))
        fail(field + ".alpha", fmt::format("roughness {} is out of range ({} to 1; use \"mirror\" for a smooth one)",
                                           mat.alpha, Material::kMinAlpha));
    }
    return mat;
  }

  void read_camera(Scene& s, const Json& cam) const {
    allow_keys(object(cam, "camera"), "camera", {"position", "look_at", "up", "fov_y_deg"});
    const Vec3f eye = vec3(member(cam, "position", "camera"), "camera.position");
    const Vec3f target = vec3(member(cam, "look_at", "camera"), "camera.look_at");
    const Vec3f up = cam.contains("up") ? vec3(cam["up"], "camera.up") : Vec3f{0, 1, 0};
    const float fov = number(member(cam, "fov_y_deg", "camera"), "camera.fov_y_deg");
    if (!(fov > 0 && fov < 180)) fail("camera.fov_y_deg", fmt::format("{} is not between 0 and 180 degrees", fov));
    if (is_zero(target - eye)) fail("camera.look_at", "is the camera position itself: no view direction");
    if (is_zero(cross(normalize(target - eye), up)))
      fail("camera.up", "is zero or parallel to the view direction (position to look_at)");
    s.camera = Camera::look_at(eye, target, up, fov);
  }

  // One transform: {"scale": s or [sx, sy, sz], "rotate": {"axis": [x, y, z], "angle":
  // degrees}, "translate": [x, y, z]} applied in that order (p' = T R S p), or {"matrix":
  // 3x4 or 4x4 rows}; or an array of such objects applied first to last.
  Affine read_transform(const Json& t, const std::string& tf) const {
    if (t.is_array()) {
      Affine a;
      for (size_t i = 0; i < t.size(); ++i) a = read_transform(object(t[i], fmt::format("{}[{}]", tf, i)), fmt::format("{}[{}]", tf, i)) * a;
      return a;
    }
    allow_keys(object(t, tf), tf, {"scale", "rotate", "translate", "matrix"});
    Affine a;
    if (t.contains("matrix")) {
      if (t.size() != 1) fail(tf + ".matrix", "cannot be combined with scale, rotate or translate in one object (use an array of transforms)");
      const Json& m = t["matrix"];
      const std::string mf = tf + ".matrix";
      if (!m.is_array() || (m.size() != 3 && m.size() != 4)) fail(mf, "expected 3 or 4 rows of 4 numbers, got " + got(m));
      double rows[4][4];
      for (size_t r = 0; r < m.size(); ++r) {
        const std::string rf = fmt::format("{}[{}]", mf, r);
        if (!m[r].is_array() || m[r].size() != 4) fail(rf, "expected a row of 4 numbers, got " + got(m[r]));
        for (size_t c = 0; c < 4; ++c) rows[r][c] = number(m[r][c], fmt::format("{}[{}]", rf, c));
      }
      if (m.size() == 4 && !(rows[3][0] == 0 && rows[3][1] == 0 && rows[3][2] == 0 && rows[3][3] == 1))
        fail(mf + "[3]", "the last row of an affine transform must be [0, 0, 0, 1] (projective transforms are not supported)");
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) a.m[r][c] = rows[r][c];
      if (!(std::fabs(a.determinant()) > 0)) fail(mf, "is singular: it flattens the mesh");
      return a;
    }
    if (t.contains("scale")) {
      const Json& sc = t["scale"];
      const Vec3f scale = sc.is_array() ? vec3(sc, tf + ".scale") : Vec3f{1, 1, 1} * number(sc, tf + ".scale");
      if (scale.x == 0 || scale.y == 0 || scale.z == 0) fail(tf + ".scale", "a zero scale flattens the mesh");
      a = Affine::scale(scale.x, scale.y, scale.z);
    }
    if (t.contains("rotate")) {
      const std::string rf = tf + ".rotate";
      const Json& r = t["rotate"];
      allow_keys(object(r, rf), rf, {"axis", "angle"});
      const Vec3f axis = vec3(member(r, "axis", rf), rf + ".axis");
      if (is_zero(axis)) fail(rf + ".axis", "is zero: no axis to rotate about");
      a = Affine::rotate(axis.x, axis.y, axis.z, number(member(r, "angle", rf), rf + ".angle")) * a;
    }
    if (t.contains("translate")) {
      const Vec3f d = vec3(t["translate"], tf + ".translate");
      a = Affine::translate(d.x, d.y, d.z) * a;
    }
    return a;
  }

  // {"file": OBJ, PLY or OFF, "material": name (optional for an OBJ: its own MTL
  // materials), "transform": T} or, instanced, {"file", "material", "instances": [T, T,
  // ...]}; "subdivide": N refines the mesh N times (Loop) before it is placed. A file
  // "data:REL" is REL in pathbench's data folder (data_dir.h), else relative to the JSON.
  void read_mesh(Scene& s, const Json& m, const std::string& field) const {
    allow_keys(object(m, field), field, {"file", "material", "transform", "instances", "subdivide"});
    const std::string file = string(member(m, "file", field), field + ".file");
    int subdivide = 0;
    if (m.contains("subdivide")) {
      const Json& n = m["subdivide"];
      if (!n.is_number_integer() || n.get<int64_t>() < 0 || n.get<int64_t>() > 8)
        fail(field + ".subdivide", "expected a whole number of Loop subdivision levels from 0 to 8, got " + got(n));
      subdivide = int(n.get<int64_t>());
    }
    const bool own_materials = !m.contains("material");
    const uint32_t mat = own_materials ? 0 : material(s, m["material"], field + ".material");
    if (m.contains("transform") && m.contains("instances"))
      fail(field + ".instances", "give either \"transform\" (one placement) or \"instances\" (several), not both");
    std::vector<Affine> placements;
    if (m.contains("instances")) {
      const Json& list = array(m["instances"], field + ".instances");
      if (list.empty()) fail(field + ".instances", "is empty: give at least one transform");
      if (s.instances.size() + list.size() > limits::kMaxPlacements)
        fail(field + ".instances", fmt::format("{} more placements: the scene may place meshes at most {} times in all "
                                               "(the supported maximum)", list.size(), limits::kMaxPlacements));
      placements.reserve(list.size());
      for (size_t i = 0; i < list.size(); ++i)
        placements.push_back(read_transform(list[i], fmt::format("{}.instances[{}]", field, i)));
    } else {
      placements.push_back(m.contains("transform") ? read_transform(m["transform"], field + ".transform") : Affine());
    }
    const fs::path path = is_data_path(file) ? fs::path(resolve_data_path(file)) : fs::path(path_).parent_path() / file;
    if (!read_.exists(path.string())) {
      if (is_data_path(file)) fail(field + ".file", missing_data_message(file));
      fail(field + ".file", fmt::format("'{}': no such file (looked for {})", file, path.string()));
    }
    MeshData mesh;
    try {
      mesh = read_mesh_file(path.string(), own_materials, read_, losses_, mesh_bytes_);
      if (subdivide > 0) mesh = loop_subdivide(mesh, subdivide);
    } catch (const InputError& e) {
      if (std::string_view(e.what()).rfind(path_ + ": ", 0) == 0) throw;  // already names this file
      fail(field, e.what());
    }
    std::vector<uint32_t> mats{mat};
    if (own_materials) mats = own_material_ids(s, mesh, file);
    if (m.contains("instances")) {
      const uint32_t proto = add_prototype(s, file, mesh, mats);
      for (const Affine& a : placements) add_instance(s, proto, a);
    } else {
      append_mesh(s, mesh, placements[0], mats);
    }
  }

  // A mesh without "material": its OBJ's MTL materials join the scene as "FILE:NAME";
  // faces without one (and PLY meshes) get a grey default, with a note.
  std::vector<uint32_t> own_material_ids(Scene& s, const MeshData& mesh, const std::string& file) const {
    std::vector<uint32_t> scene_ids;
    for (size_t i = 0; i < mesh.materials.size(); ++i)
      scene_ids.push_back(scenes::append_material(s, file + ":" + mesh.material_names[i], mesh.materials[i]));
    std::vector<uint32_t> ids(mesh.triangles.size());
    uint32_t grey = ~0u;
    for (size_t i = 0; i < ids.size(); ++i) {
      const int m = mesh.material_ids[i];
      if (m >= 0) {
        ids[i] = scene_ids[size_t(m)];
        continue;
      }
      if (grey == ~0u) {
        grey = scenes::add_material(s, file + ":default", {0.5f, 0.5f, 0.5f});
        scene_note(fmt::format("{}: mesh '{}' has faces without a material (no \"material\" given, none from an MTL "
                               "file); they get a grey default (albedo 0.5)", path_, file));
      }
      ids[i] = grey;
    }
    return ids;
  }

  void read_triangles(Scene& s, const Json& g, const std::string& field) const {
    allow_keys(object(g, field), field, {"vertices", "indices", "material"});
    const Json& vertices = array(member(g, "vertices", field), field + ".vertices");
    const Json& indices = array(member(g, "indices", field), field + ".indices");
    const uint32_t mat = material(s, member(g, "material", field), field + ".material");
    if (s.triangles.size() + indices.size() - instanced_triangles(s) > limits::kMaxTriangles)
      fail(field + ".indices", fmt::format("the scene has more than {} triangles (the supported maximum)",
                                           limits::kMaxTriangles));
    const uint32_t base = uint32_t(s.positions.size());
    for (size_t i = 0; i < vertices.size(); ++i)
      s.positions.push_back(vec3(vertices[i], fmt::format("{}.vertices[{}]", field, i)));
    for (size_t i = 0; i < indices.size(); ++i) {
      const std::string tf = fmt::format("{}.indices[{}]", field, i);
      const Json& t = indices[i];
      if (!t.is_array() || t.size() != 3) fail(tf, "expected an array of 3 vertex indices, got " + got(t));
      uint32_t v[3];
      for (int k = 0; k < 3; ++k) {
        const std::string kf = fmt::format("{}[{}]", tf, k);
        if (!t[k].is_number_integer())
          fail(kf, "expected a vertex index (a whole number), got " + got(t[k]));
        const int64_t idx = t[k].get<int64_t>();
        if (idx < 0 || uint64_t(idx) >= vertices.size())
          fail(kf, fmt::format("vertex index {} is out of range (this group has {} vertices, 0 to {})", idx,
                               vertices.size(), int64_t(vertices.size()) - 1));
        v[k] = base + uint32_t(idx);
      }
      scenes::add_triangle(s, v[0], v[1], v[2], mat);
    }
  }
};

}  // namespace

Scene parse_scene_json(const std::string& path, const std::string& text, const FileReader& read, const Losses& losses) {
  return JsonSceneReader(path, read, losses).read(text);
}

}  // namespace pb::scene_io
