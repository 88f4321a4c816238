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

#include "pathbench/common/errors.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/json_input.h"
#include "pathbench/common/limits.h"
#include "pathbench/common/scene_library.h"
#include "scene_io/scene_io.h"
#include "scenes/builder.h"

namespace pb::scene_io {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------
// JSON.

using Json = nlohmann::ordered_json;  // keeps the materials in file order

class JsonSceneReader {
 public:
  JsonSceneReader(std::string path, const FileReader& read) : path_(std::move(path)), read_(read) {}

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
    const Json& materials = member(root, "materials", "");
    if (!materials.is_object() || materials.empty())
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
    s.finalize();
    return s;
  }

 private:
  std::string path_;
  const FileReader& read_;
  mutable uint64_t mesh_bytes_ = 0;
  mutable std::unordered_map<std::string, uint32_t> material_index_;  // name -> first material of that name  // all mesh files read so far: one budget for the scene

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
    // A map, not a search per use: many groups times many materials stays linear.
    if (material_index_.size() != s.material_names.size()) {
      material_index_.clear();
      for (size_t i = 0; i < s.material_names.size(); ++i) material_index_.emplace(s.material_names[i], uint32_t(i));
    }
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

  void read_mesh(Scene& s, const Json& m, const std::string& field) const {
    allow_keys(object(m, field), field, {"file", "material", "transform"});
    const std::string file = string(member(m, "file", field), field + ".file");
    const uint32_t mat = material(s, member(m, "material", field), field + ".material");
    Vec3f scale{1, 1, 1}, translate{0, 0, 0};
    if (m.contains("transform")) {
      const Json& t = m["transform"];
      const std::string tf = field + ".transform";
      allow_keys(object(t, tf), tf, {"scale", "translate"});
      if (t.contains("scale")) {
        const Json& sc = t["scale"];
        scale = sc.is_array() ? vec3(sc, tf + ".scale") : Vec3f{1, 1, 1} * number(sc, tf + ".scale");
        if (scale.x == 0 || scale.y == 0 || scale.z == 0) fail(tf + ".scale", "a zero scale flattens the mesh");
      }
      if (t.contains("translate")) translate = vec3(t["translate"], tf + ".translate");
    }
    const fs::path obj = fs::path(path_).parent_path() / file;
    if (!read_.exists(obj.string())) fail(field + ".file", fmt::format("'{}': no such file (looked for {})", file, obj.string()));
    try {
      const std::string text = read_.read(obj.string(), "mesh file (OBJ)", limits::kMaxMeshBytes);
      mesh_bytes_ += text.size();
      if (mesh_bytes_ > limits::kMaxMeshBytes)
        fail(field + ".file", fmt::format("the mesh files (OBJ) of one scene are limited to {} in all",
                                          format_bytes(limits::kMaxMeshBytes)));
      append_obj_mesh(s, obj.string(), text, scale, translate, mat);
    } catch (const InputError& e) {
      if (std::string_view(e.what()).rfind(path_ + ": ", 0) == 0) throw;  // already names this file
      fail(field, e.what());
    }
  }

  void read_triangles(Scene& s, const Json& g, const std::string& field) const {
    allow_keys(object(g, field), field, {"vertices", "indices", "material"});
    const Json& vertices = array(member(g, "vertices", field), field + ".vertices");
    const Json& indices = array(member(g, "indices", field), field + ".indices");
    const uint32_t mat = material(s, member(g, "material", field), field + ".material");
    if (s.triangles.size() + indices.size() > limits::kMaxTriangles)
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

Scene parse_scene_json(const std::string& path, const std::string& text, const FileReader& read) {
  return JsonSceneReader(path, read).read(text);
}

}  // namespace pb::scene_io

namespace pb {

Scene load_scene_json(const std::string& path) {
  return scene_io::parse_scene_json(path, read_input_file(path, "scene file (JSON)", limits::kMaxSceneJsonBytes),
                                    scene_io::disk_reader());
}

}  // namespace pb
