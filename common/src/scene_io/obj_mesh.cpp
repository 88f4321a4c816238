// OBJ meshes, checked line by line before tinyobjloader reads them (obj_mesh.h).
#include "obj_mesh.h"

#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>

#include "pathbench/common/errors.h"

namespace pb::scene_io {

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

namespace {

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


}  // namespace

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

}  // namespace pb::scene_io
