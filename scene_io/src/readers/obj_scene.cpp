// OBJ meshes (with their MTL materials): a bare .obj scene, or a mesh of a JSON scene.
// tinyobjloader parses, but it skips what it cannot parse (a bad number becomes 0, an
// unknown line is ignored, an out-of-range index is kept), so a first pass checks
// every line and reports the first problem with its line number; it also counts what
// tinyobjloader would allocate, so a small file cannot ask for gigabytes. MTL files
// are read through the FileReader (regular files only, bounded), never by
// tinyobjloader itself.
#include <fmt/core.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <istream>
#include <set>
#include <streambuf>
#include <string_view>
#include <unordered_set>

#include "pathbench/common/scene_warnings.h"
#include "pathbench/common/errors.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/limits.h"
#include "pathbench/scene_io/scene_library.h"
#include "readers/readers.h"
#include "scenes/builder.h"

namespace pb::scene_io {

namespace {

namespace fs = std::filesystem;

struct ObjData {
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

// Groups and objects: tinyobjloader makes a shape (a few hundred bytes) of each.
constexpr uint64_t kMaxGroups = uint64_t(1) << 20;

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
struct ObjCheck {
  std::vector<UsedMaterial> used;  // the `usemtl` names with their lines
  uint64_t normals = 0, texcoords = 0;  // `vn` and `vt` lines (not modelled)
};

// Checks the OBJ text line by line.
ObjCheck check_obj_text(const std::string& path, const std::string& text, bool with_materials,
                                         const FileReader& files) {
  auto fail = [&](size_t line, const std::string& what) {
    throw InputError(fmt::format("{}:{}: {}", path, line, what));
  };
  ObjCheck check;
  std::vector<UsedMaterial>& used = check.used;
  int64_t vertices = 0;
  int64_t max_ref = 0;  // the largest absolute vertex index, and its line
  size_t max_ref_line = 0;
  uint64_t triangles = 0, references = 0, groups = 0, usemtl = 0;
  size_t line_no = 0;
  for (size_t start = 0; start < text.size();) {
    // Lines end at "\n", "\r\n" or a lone "\r", as tinyobjloader splits them: a file
    // of "\r"-separated lines must not pass this check as one long line.
    size_t end = text.find_first_of("\r\n", start);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + start, end - start);
    start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    ++line_no;
    if (line.find('\0') != std::string_view::npos) fail(line_no, "binary data: this is not a text OBJ file");
    if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    const auto tok = split_ws(line);
    if (tok.empty()) continue;
    const std::string_view kw = tok[0];
    if (!kObjStatements.count(kw)) fail(line_no, fmt::format("unknown OBJ statement '{:.40}'", kw));
    if (kw == "v" || kw == "vt" || kw == "vn" || kw == "vp") {
      const size_t need = kw == "v" || kw == "vn" ? 3 : 1;
      if (tok.size() - 1 < need) fail(line_no, fmt::format("'{}' needs at least {} numbers", kw, need));
      if (tok.size() - 1 > 7) fail(line_no, fmt::format("'{}' has more than 7 numbers", kw));
      for (size_t i = 1; i < tok.size(); ++i) {
        double x;
        if (!parse_whole(tok[i], x)) fail(line_no, fmt::format("'{:.40}' is not a number", tok[i]));
        if (kw == "v" && i <= 3 && !std::isfinite(float(x)))
          fail(line_no, fmt::format("vertex coordinate '{:.40}' is NaN or infinite (or too large for a float)", tok[i]));
      }
      if (kw == "v") ++vertices;
      if (kw == "vn") ++check.normals;
      if (kw == "vt") ++check.texcoords;
    } else if (kw == "f" || kw == "l" || kw == "p") {
      const size_t n = tok.size() - 1;
      if (kw == "f" && n < 3) fail(line_no, "a face needs at least 3 vertices");
      if (n > 255) fail(line_no, fmt::format("'{}' has more than 255 vertices", kw));
      if (kw == "f") triangles += n - 2;
      references += n;
      if (triangles > limits::kMaxTriangles)
        fail(line_no, fmt::format("more than {} triangles: the supported maximum per scene", limits::kMaxTriangles));
      if (references > 3 * limits::kMaxTriangles)
        fail(line_no, fmt::format("more than {} face, line and point vertices in all (the supported maximum)",
                                  3 * limits::kMaxTriangles));
      for (size_t i = 1; i < tok.size(); ++i) {
        // v, v/vt, v//vn or v/vt/vn: every index present must be a non-zero integer.
        std::string_view rest = tok[i];
        for (int part = 0; part < 3 && !rest.empty(); ++part) {
          const size_t slash = rest.find('/');
          const std::string_view idx = rest.substr(0, slash);
          rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
          if (idx.empty() && part > 0) continue;
          int64_t k = 0;
          if (!parse_whole(idx, k))
            fail(line_no, fmt::format("face vertex '{:.40}': '{:.40}' is not an index", tok[i], idx));
          if (k == 0) fail(line_no, fmt::format("face vertex '{:.40}': index 0 (OBJ indices start at 1)", tok[i]));
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
    } else if (kw == "g" || kw == "o") {
      if (++groups > kMaxGroups) fail(line_no, fmt::format("more than {} groups and objects ('g', 'o')", kMaxGroups));
    } else if (kw == "usemtl") {
      if (tok.size() < 2) fail(line_no, "'usemtl' needs a material name");
      // tinyobjloader warns (a string per use) about unknown names: bounded here.
      if (++usemtl > kMaxGroups) fail(line_no, fmt::format("more than {} 'usemtl' statements", kMaxGroups));
      used.push_back({std::string(tok[1]), line_no});
    } else if (kw == "mtllib" && with_materials) {
      if (tok.size() < 2) fail(line_no, "'mtllib' needs a file name");
      for (size_t i = 1; i < tok.size(); ++i) {
        const fs::path mtl = fs::path(path).parent_path() / std::string(tok[i]);
        if (!files.exists(mtl.string()))
          fail(line_no, fmt::format("material library '{:.80}' not found (looked for {:.200})", tok[i], mtl.string()));
      }
    }
  }
  if (max_ref > vertices)
    fail(max_ref_line, fmt::format("face refers to vertex {}, but the file has only {} vertices", max_ref, vertices));
  return check;
}

// tinyobjloader's number parser overflows a signed int (undefined behaviour) on an
// exponent of ten or more digits, and OBJ lines are checked before it sees them but
// MTL lines are not: refuse such exponents (no real number needs one).
void check_mtl_exponents(const std::string& path, const std::string& text) {
  for (size_t i = 1; i + 1 < text.size(); ++i) {
    if ((text[i] != 'e' && text[i] != 'E') || !(std::isdigit(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '.'))
      continue;
    size_t j = i + 1;
    if (text[j] == '+' || text[j] == '-') ++j;
    size_t digits = 0;
    while (j < text.size() && std::isdigit(static_cast<unsigned char>(text[j]))) ++j, ++digits;
    if (digits > 8)
      throw InputError(fmt::format("{}: a number with an exponent of {} digits (at byte {})", path, digits, i));
  }
}

// A read-only istream over text already in memory (no copy).
struct MemoryBuf : std::streambuf {
  explicit MemoryBuf(const std::string& s) {
    char* p = const_cast<char*>(s.data());
    setg(p, p, p + s.size());
  }
};

// tinyobjloader asks this for each `mtllib` file: read through the FileReader, with
// one byte budget for all of the OBJ's libraries (a material costs ~1 KB parsed).
class MtlReader : public tinyobj::MaterialReader {
 public:
  MtlReader(const std::string& obj_path, const FileReader& read) : dir_(fs::path(obj_path).parent_path()), read_(read) {}
  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* map, std::string* warn, std::string* err) override {
    const std::string path = (dir_ / name).string();
    const std::string text = read_.read(path, "material library (MTL)", limits::kMaxMtlBytes);
    used_ += text.size();
    if (used_ > limits::kMaxMtlBytes)
      throw InputError(fmt::format("{}: the material libraries (MTL) of one OBJ are limited to {} in all", path,
                                   format_bytes(limits::kMaxMtlBytes)));
    if (text.find('\0') != std::string::npos) throw InputError(fmt::format("{}: binary data: not a text MTL file", path));
    check_mtl_exponents(path, text);
    MemoryBuf buf(text);
    std::istream in(&buf);
    tinyobj::LoadMtl(map, materials, &in, warn, err);
    return true;
  }

 private:
  fs::path dir_;
  const FileReader& read_;
  uint64_t used_ = 0;
};

ObjData read_obj(const std::string& path, const std::string& text, bool with_materials, const FileReader& read,
                 const Losses& losses) {
  const ObjCheck check = check_obj_text(path, text, with_materials, read);
  const std::vector<UsedMaterial>& used = check.used;
  if (check.normals)
    losses.report(path, fmt::format("{} vertex normals (vn): shading uses the geometric normal", check.normals));

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  ObjData mesh;
  std::string warn, err;
  MtlReader mtl(path, read);
  MemoryBuf buf(text);
  std::istream in(&buf);
  bool ok;
  try {
    ok = tinyobj::LoadObj(&attrib, &shapes, &mesh.materials, &warn, &err, &in, with_materials ? &mtl : nullptr,
                          /*triangulate=*/true, /*default_vcols_fallback=*/false);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()));
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == '.')) err.pop_back();
    throw InputError(fmt::format("{}: malformed OBJ: {:.200}", path, err.empty() ? "tinyobjloader failed" : err));
  }
  const auto& v = attrib.vertices;
  mesh.positions.reserve(v.size() / 3);
  for (size_t i = 0; i + 2 < v.size(); i += 3) mesh.positions.push_back({v[i], v[i + 1], v[i + 2]});
  if (with_materials) {
    std::unordered_set<std::string_view> names;  // a set: many uses times many materials stays linear
    for (const tinyobj::material_t& m : mesh.materials) names.insert(m.name);
    for (const UsedMaterial& u : used) {
      if (!names.count(u.name))
        throw InputError(fmt::format("{}:{}: usemtl '{:.80}': no such material in the file's material libraries (mtllib)",
                                     path, u.line, u.name));
    }
    if (!warn.empty()) {
      while (!warn.empty() && warn.back() == '\n') warn.pop_back();
      if (warn.size() > 2000) warn = warn.substr(0, 2000) + "...";
      scene_warning(fmt::format("{}: {}", path, warn));
    }
  }
  const uint32_t nv = uint32_t(mesh.positions.size());
  for (const tinyobj::shape_t& shape : shapes) {
    size_t offset = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const size_t n = shape.mesh.num_face_vertices[f];
      const int mat = with_materials && f < shape.mesh.material_ids.size() ? shape.mesh.material_ids[f] : -1;
      for (size_t k = 0; k < n; ++k) {
        const int idx = shape.mesh.indices[offset + k].vertex_index;
        if (idx < 0 || uint32_t(idx) >= nv)
          throw InputError(fmt::format("{}: shape '{:.80}' face {} refers to vertex {}, but there are only {}", path,
                                       shape.name, f, int64_t(idx) + 1, nv));
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

// MTL colours are clamped to [0, 1]; NaN (which clamp passes through) becomes 0.
Vec3f clamp01(const tinyobj::real_t* c) {
  auto one = [](float x) { return std::isnan(x) ? 0.0f : std::clamp(x, 0.0f, 1.0f); };
  return {one(float(c[0])), one(float(c[1])), one(float(c[2]))};
}

// What an MTL material holds beyond Kd and Ke, named for Losses.
void report_mtl_losses(const std::string& path, const tinyobj::material_t& m, const Losses& losses) {
  const std::pair<const char*, const std::string*> maps[] = {
      {"map_Kd", &m.diffuse_texname},   {"map_Ks", &m.specular_texname}, {"map_Ka", &m.ambient_texname},
      {"map_Ns", &m.specular_highlight_texname}, {"bump", &m.bump_texname}, {"map_d", &m.alpha_texname},
      {"disp", &m.displacement_texname}, {"refl", &m.reflection_texname}, {"norm", &m.normal_texname},
      {"map_Ke", &m.emissive_texname},  {"map_Pr", &m.roughness_texname}, {"map_Pm", &m.metallic_texname}};
  for (const auto& [key, name] : maps)
    if (!name->empty()) losses.report(path, fmt::format("material '{:.80}': texture {} '{:.80}'", m.name, key, *name));
  if (m.specular[0] > 0 || m.specular[1] > 0 || m.specular[2] > 0)
    losses.report(path, fmt::format("material '{:.80}': specular reflection Ks (diffuse only)", m.name));
  if (m.dissolve < 1) losses.report(path, fmt::format("material '{:.80}': transparency d/Tr", m.name));
}

}  // namespace

MeshData read_obj_mesh(const std::string& path, const std::string& text, bool with_materials, const FileReader& read,
                       const Losses& losses) {
  ObjData obj = read_obj(path, text, with_materials, read, losses);
  MeshData mesh{std::move(obj.positions), std::move(obj.triangles), std::move(obj.material_ids), {}, {}};
  for (const tinyobj::material_t& m : obj.materials) {
    report_mtl_losses(path, m, losses);
    mesh.materials.push_back({clamp01(m.diffuse), {float(m.emission[0]), float(m.emission[1]), float(m.emission[2])}});
    mesh.material_names.push_back(m.name);
  }
  return mesh;
}

Scene parse_scene_obj(const std::string& path, const std::string& text, const FileReader& read, const Losses& losses) {
  MeshData mesh = read_obj_mesh(path, text, true, read, losses);
  Scene s;
  s.name = path;
  s.positions = std::move(mesh.positions);
  for (size_t i = 0; i < mesh.materials.size(); ++i) scenes::append_material(s, mesh.material_names[i], mesh.materials[i]);
  uint32_t default_material = ~0u;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    uint32_t mat;
    if (mesh.material_ids[i] >= 0) {
      mat = uint32_t(mesh.material_ids[i]);
    } else {
      if (default_material == ~0u) default_material = scenes::add_material(s, "default", {0.5f, 0.5f, 0.5f});
      mat = default_material;
    }
    const Triangle& t = mesh.triangles[i];
    scenes::add_triangle(s, t.v[0], t.v[1], t.v[2], mat);
  }
  frame_bare_mesh(s, path, true, "MTL Ke");
  return s;
}

}  // namespace pb::scene_io
