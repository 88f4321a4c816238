// JSON scene descriptions (scenes/README.md gives the format). Every problem with a file
// is one InputError naming the file and the JSON field.
#include <fmt/core.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string_view>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"
#include "scene_io/obj_mesh.h"
#include "scenes/builder.h"


namespace pb {

namespace {

namespace fs = std::filesystem;
using scene_io::clamp01;
using scene_io::ObjMesh;
using scene_io::read_obj;
using scene_io::read_text_file;

using Json = nlohmann::ordered_json;  // keeps the materials in file order

class JsonSceneReader {
 public:
  explicit JsonSceneReader(std::string path) : path_(std::move(path)) {}

  Scene read() {
    const std::string text = read_text_file(path_);
    Json root;
    try {
      root = Json::parse(text);
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
    for (const auto& [key, value] : obj.items()) {
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
    for (size_t i = 0; i < s.material_names.size(); ++i)
      if (s.material_names[i] == name) return uint32_t(i);
    std::string known;
    for (const std::string& n : s.material_names) known += (known.empty() ? "" : ", ") + n;
    fail(field, fmt::format("unknown material '{}' (the file defines: {})", name, known));
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
    if (!fs::exists(obj)) fail(field + ".file", fmt::format("'{}': no such file (looked for {})", file, obj.string()));
    ObjMesh mesh;
    try {
      mesh = read_obj(obj.string(), false);
    } catch (const InputError& e) {
      fail(field, e.what());
    }
    const uint32_t base = uint32_t(s.positions.size());
    for (const Vec3f& p : mesh.positions) s.positions.push_back(p * scale + translate);
    for (const Triangle& t : mesh.triangles) scenes::add_triangle(s, base + t.v[0], base + t.v[1], base + t.v[2], mat);
  }

  void read_triangles(Scene& s, const Json& g, const std::string& field) const {
    allow_keys(object(g, field), field, {"vertices", "indices", "material"});
    const Json& vertices = array(member(g, "vertices", field), field + ".vertices");
    const Json& indices = array(member(g, "indices", field), field + ".indices");
    const uint32_t mat = material(s, member(g, "material", field), field + ".material");
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

Scene load_scene_json(const std::string& path) { return JsonSceneReader(path).read(); }

}  // namespace pb
