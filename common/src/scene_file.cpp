// Scene files: JSON scene descriptions (scenes/README.md gives the format) and bare
// OBJ meshes (with their MTL materials). Every problem with a file is one InputError
// naming the file and, where there is one, the line or the JSON field.
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
#include "scenes/builder.h"

namespace pb {

namespace {

namespace fs = std::filesystem;

std::string read_text_file(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(fmt::format("{}: no such file", path));
  if (fs::is_directory(path, ec)) throw InputError(fmt::format("{}: is a directory, not a scene file", path));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open for reading", path));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(fmt::format("{}: read failed", path));
  return text.str();
}

// ---------------------------------------------------------------------------------
// OBJ. tinyobjloader reads the file, but it skips what it cannot parse (a bad number
// becomes 0, an unknown line is ignored, an out-of-range index is kept), so a first
// pass checks every line and reports the first problem with its line number.

struct ObjMesh {
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<int> material_ids;  // per triangle: index into `materials`, or -1 (none)
  std::vector<tinyobj::material_t> materials;
};

const std::set<std::string_view> kObjStatements = {
    "v",    "vt",  "vn",    "vp",    "f",    "l",     "p",     "g",     "o",       "s",          "mg",
    "usemtl", "mtllib", "maplib", "usemap", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf",
    "parm", "trim", "hole", "scrv", "sp", "end", "con", "lod", "shadow_obj", "trace_obj", "ctech", "stech",
    "bevel", "c_interp", "d_interp"};

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

// The whole token as a number (from_chars, plus the leading '+' that OBJ writers use).
template <class T> bool parse_whole(std::string_view tok, T& v) {
  if (tok.size() > 1 && tok[0] == '+' && tok[1] != '-') tok.remove_prefix(1);
  auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  return ec == std::errc() && ptr == tok.data() + tok.size();
}

struct UsedMaterial {
  std::string name;
  size_t line;
};

// Checks the OBJ text line by line; returns the `usemtl` names with their lines.
std::vector<UsedMaterial> check_obj_text(const std::string& path, const std::string& text, bool with_materials) {
  auto fail = [&](size_t line, const std::string& what) {
    throw InputError(fmt::format("{}:{}: {}", path, line, what));
  };
  std::vector<UsedMaterial> used;
  int64_t vertices = 0;
  int64_t max_ref = 0;  // the largest absolute vertex index, and its line
  size_t max_ref_line = 0;
  size_t line_no = 0;
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + start, end - start);
    start = end + 1;
    ++line_no;
    if (line.find('\0') != std::string_view::npos) fail(line_no, "binary data: this is not a text OBJ file");
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto tok = split_ws(line);
    if (tok.empty()) continue;
    const std::string_view kw = tok[0];
    if (!kObjStatements.count(kw)) fail(line_no, fmt::format("unknown OBJ statement '{}'", kw));
    if (kw == "v" || kw == "vt" || kw == "vn" || kw == "vp") {
      const size_t need = kw == "v" || kw == "vn" ? 3 : 1;
      if (tok.size() - 1 < need) fail(line_no, fmt::format("'{}' needs at least {} numbers", kw, need));
      for (size_t i = 1; i < tok.size(); ++i) {
        double x;
        if (!parse_whole(tok[i], x)) fail(line_no, fmt::format("'{}' is not a number", tok[i]));
        if (kw == "v" && i <= 3 && !std::isfinite(float(x)))
          fail(line_no, fmt::format("vertex coordinate '{}' is NaN or infinite (or too large for a float)", tok[i]));
      }
      if (kw == "v") ++vertices;
    } else if (kw == "f") {
      if (tok.size() - 1 < 3) fail(line_no, "a face needs at least 3 vertices");
      if (tok.size() - 1 > 255) fail(line_no, "a face has more than 255 vertices");
      for (size_t i = 1; i < tok.size(); ++i) {
        // v, v/vt, v//vn or v/vt/vn: every index present must be a non-zero integer.
        std::string_view rest = tok[i];
        for (int part = 0; part < 3 && !rest.empty(); ++part) {
          const size_t slash = rest.find('/');
          const std::string_view idx = rest.substr(0, slash);
          rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
          if (idx.empty() && part > 0) continue;
          int64_t k = 0;
          if (!parse_whole(idx, k)) fail(line_no, fmt::format("face vertex '{}': '{}' is not an index", tok[i], idx));
          if (k == 0) fail(line_no, fmt::format("face vertex '{}': index 0 (OBJ indices start at 1)", tok[i]));
          if (part != 0) continue;
          // Relative indices count back from the vertices read so far; absolute ones
          // may refer forward, so they are checked against the total at the end.
          if (k < 0 && vertices + k < 0)
            fail(line_no, fmt::format("face vertex index {} reaches before the first vertex ({} read so far)", k,
                                      vertices));
          if (k > max_ref) {
            max_ref = k;
            max_ref_line = line_no;
          }
        }
      }
    } else if (kw == "usemtl") {
      if (tok.size() < 2) fail(line_no, "'usemtl' needs a material name");
      used.push_back({std::string(tok[1]), line_no});
    } else if (kw == "mtllib" && with_materials) {
      if (tok.size() < 2) fail(line_no, "'mtllib' needs a file name");
      for (size_t i = 1; i < tok.size(); ++i) {
        const fs::path mtl = fs::path(path).parent_path() / std::string(tok[i]);
        if (!fs::exists(mtl)) fail(line_no, fmt::format("material library '{}' not found (looked for {})", tok[i], mtl.string()));
      }
    }
  }
  if (max_ref > vertices)
    fail(max_ref_line, fmt::format("face refers to vertex {}, but the file has only {} vertices", max_ref, vertices));
  return used;
}

ObjMesh read_obj(const std::string& path, bool with_materials) {
  const std::string text = read_text_file(path);
  const std::vector<UsedMaterial> used = check_obj_text(path, text, with_materials);

  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    std::string err = reader.Error();
    while (!err.empty() && (err.back() == '\n' || err.back() == '.')) err.pop_back();
    throw InputError(fmt::format("{}: malformed OBJ: {}", path, err.empty() ? "tinyobjloader failed" : err));
  }
  ObjMesh mesh;
  const auto& v = reader.GetAttrib().vertices;
  mesh.positions.reserve(v.size() / 3);
  for (size_t i = 0; i + 2 < v.size(); i += 3) mesh.positions.push_back({v[i], v[i + 1], v[i + 2]});
  if (with_materials) {
    mesh.materials = reader.GetMaterials();
    for (const UsedMaterial& u : used) {
      const bool known = std::any_of(mesh.materials.begin(), mesh.materials.end(),
                                     [&](const tinyobj::material_t& m) { return m.name == u.name; });
      if (!known)
        throw InputError(fmt::format("{}:{}: usemtl '{}': no such material in the file's material libraries (mtllib)",
                                     path, u.line, u.name));
    }
    if (!reader.Warning().empty()) {
      std::string warn = reader.Warning();
      while (!warn.empty() && warn.back() == '\n') warn.pop_back();
      fmt::print(stderr, "warning: {}: {}\n", path, warn);
    }
  }
  const uint32_t nv = uint32_t(mesh.positions.size());
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t offset = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const size_t n = shape.mesh.num_face_vertices[f];
      const int mat = with_materials && f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1;
      for (size_t k = 0; k < n; ++k) {
        const int idx = shape.mesh.indices[offset + k].vertex_index;
        if (idx < 0 || uint32_t(idx) >= nv)
          throw InputError(fmt::format("{}: shape '{}' face {} refers to vertex {}, but there are only {}", path,
                                       shape.name, f, idx + 1, nv));
      }
      // Triangulated already; a fan covers anything tinyobjloader left as a polygon.
      for (size_t k = 1; k + 1 < n; ++k) {
        mesh.triangles.push_back({{uint32_t(shape.mesh.indices[offset].vertex_index),
                                   uint32_t(shape.mesh.indices[offset + k].vertex_index),
                                   uint32_t(shape.mesh.indices[offset + k + 1].vertex_index)}});
        mesh.material_ids.push_back(mat < 0 || size_t(mat) >= mesh.materials.size() ? -1 : mat);
      }
      offset += n;
    }
  }
  if (mesh.triangles.empty()) throw InputError(fmt::format("{}: the OBJ file has no faces", path));
  return mesh;
}

Vec3f clamp01(const tinyobj::real_t* c) {
  return {std::clamp(float(c[0]), 0.0f, 1.0f), std::clamp(float(c[1]), 0.0f, 1.0f), std::clamp(float(c[2]), 0.0f, 1.0f)};
}

// ---------------------------------------------------------------------------------
// JSON.

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

Scene load_scene_json(const std::string& path) { return JsonSceneReader(path).read(); }

Scene load_scene_obj(const std::string& path) {
  ObjMesh mesh = read_obj(path, true);
  Scene s;
  s.name = path;
  s.positions = std::move(mesh.positions);
  for (const tinyobj::material_t& m : mesh.materials)
    scenes::add_material(s, m.name, clamp01(m.diffuse), {float(m.emission[0]), float(m.emission[1]), float(m.emission[2])});
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
