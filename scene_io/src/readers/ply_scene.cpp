// PLY meshes (ASCII, binary little and big endian): vertex x, y, z and faces as
// polygons, fan-triangulated. A small reader of its own: the header is checked
// line by line, every count against the bytes left (so a small file cannot ask for
// gigabytes), every index against the vertices; what else the file holds (normals,
// colours, other elements) is named through Losses.
#include <fmt/core.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "readers/readers.h"

namespace pb::scene_io {

namespace {

enum class Type { I8, U8, I16, U16, I32, U32, F32, F64 };

bool type_of(std::string_view name, Type& t) {
  static constexpr std::pair<std::string_view, Type> kTypes[] = {
      {"char", Type::I8},    {"int8", Type::I8},    {"uchar", Type::U8},    {"uint8", Type::U8},
      {"short", Type::I16},  {"int16", Type::I16},  {"ushort", Type::U16},  {"uint16", Type::U16},
      {"int", Type::I32},    {"int32", Type::I32},  {"uint", Type::U32},    {"uint32", Type::U32},
      {"float", Type::F32},  {"float32", Type::F32}, {"double", Type::F64}, {"float64", Type::F64}};
  for (const auto& [n, ty] : kTypes)
    if (n == name) return t = ty, true;
  return false;
}
size_t size_of(Type t) {
  switch (t) {
    case Type::I8: case Type::U8: return 1;
    case Type::I16: case Type::U16: return 2;
    case Type::I32: case Type::U32: case Type::F32: return 4;
    case Type::F64: return 8;
  }
  return 1;
}
bool is_integer(Type t) { return t != Type::F32 && t != Type::F64; }

struct Property {
  std::string name;
  Type type = Type::F32;
  bool list = false;
  Type count_type = Type::U8;
};
struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { Ascii, Little, Big };

class PlyReader {
 public:
  PlyReader(const std::string& path, const std::string& text) : path_(path), text_(text) {}

  MeshData read(const Losses& losses) {
    read_header();
    const Element* vertex = nullptr;
    const Element* face = nullptr;
    for (const Element& e : elements_) {
      if (e.name == "vertex" && !vertex) vertex = &e;
      else if (e.name == "face" && !face) face = &e;
      else losses.report(path_, fmt::format("element '{:.40}' ({} of them)", e.name, e.count));
    }
    if (!vertex) fail("the header declares no 'element vertex'");
    if (!face) fail("the header declares no 'element face' (a point cloud has no triangles)");
    int xyz[3] = {-1, -1, -1};
    std::string ignored;
    for (size_t i = 0; i < vertex->properties.size(); ++i) {
      const Property& p = vertex->properties[i];
      const int axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
      if (axis >= 0 && !p.list && xyz[axis] < 0) xyz[axis] = int(i);
      else ignored += (ignored.empty() ? "" : ", ") + p.name.substr(0, 40);
    }
    for (int a = 0; a < 3; ++a)
      if (xyz[a] < 0) fail(fmt::format("the vertex element has no property '{}'", "xyz"[a]));
    if (!ignored.empty()) losses.report(path_, "vertex properties " + ignored);
    int indices = -1;
    for (size_t i = 0; i < face->properties.size(); ++i) {
      const Property& p = face->properties[i];
      if ((p.name == "vertex_indices" || p.name == "vertex_index") && indices < 0) {
        if (!p.list || !is_integer(p.type))
          fail(fmt::format("face property '{}' must be a list of integers", p.name));
        indices = int(i);
      } else {
        losses.report(path_, "face property " + p.name.substr(0, 40));
      }
    }
    if (indices < 0) fail("the face element has no list property 'vertex_indices'");

    MeshData mesh;
    for (const Element& e : elements_) {
      check_count(e);
      const bool is_vertex = &e == vertex, is_face = &e == face;
      if (is_vertex) mesh.positions.reserve(e.count);
      std::vector<uint32_t> poly;
      for (uint64_t n = 0; n < e.count; ++n) {
        double v[3] = {0, 0, 0};
        for (size_t i = 0; i < e.properties.size(); ++i) {
          const Property& p = e.properties[i];
          if (!p.list) {
            const double x = value(p.type);
            for (int a = 0; a < 3; ++a)
              if (is_vertex && int(i) == xyz[a]) v[a] = x;
            continue;
          }
          const double count = value(p.count_type);
          if (!(count >= 0 && count == std::floor(count)) || count > double(limits::kMaxTriangles))
            fail(fmt::format("{} {}: list '{}' has a bad length {}", e.name, n, p.name, count));
          const bool keep = is_face && int(i) == indices;
          if (keep) poly.clear();
          for (uint64_t k = 0; k < uint64_t(count); ++k) {
            const double x = value(p.type);
            if (!keep) continue;
            if (!(x >= 0 && x < 4294967295.0)) fail(fmt::format("face {}: vertex index {} is negative or too large", n, x));
            poly.push_back(uint32_t(x));
          }
          if (keep) add_polygon(mesh, poly, n);
        }
        if (is_vertex) {
          const Vec3f p{float(v[0]), float(v[1]), float(v[2])};
          if (!is_finite(p))
            fail(fmt::format("vertex {} has a NaN or infinite coordinate (or one too large for a float)", n));
          mesh.positions.push_back(p);
        }
      }
    }
    if (format_ == Format::Ascii) {
      skip_space();
      if (pos_ < text_.size()) fail(fmt::format("data after the last element (at byte {})", pos_));
    }
    for (size_t i = 0; i < mesh.triangles.size(); ++i)
      for (uint32_t k : mesh.triangles[i].v)
        if (k >= mesh.positions.size())
          fail(fmt::format("a face refers to vertex {}, but the file has only {} vertices", k, mesh.positions.size()));
    if (mesh.triangles.empty()) fail("the file has no faces");
    mesh.material_ids.assign(mesh.triangles.size(), -1);
    return mesh;
  }

 private:
  const std::string& path_;
  const std::string& text_;
  size_t pos_ = 0;
  Format format_ = Format::Ascii;
  std::vector<Element> elements_;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: malformed PLY: {}", path_, what));
  }

  void read_header() {
    size_t line_no = 0;
    bool have_format = false;
    for (;;) {
      const size_t end = text_.find('\n', pos_);
      if (end == std::string::npos) fail("the header has no 'end_header' line");
      std::string_view line(text_.data() + pos_, end - pos_);
      pos_ = end + 1;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      ++line_no;
      std::vector<std::string_view> tok;
      for (size_t i = 0; i < line.size();) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        size_t j = i;
        while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
        if (j > i) tok.push_back(line.substr(i, j - i));
        i = j;
      }
      auto bad = [&](const std::string& what) { fail(fmt::format("header line {}: {}", line_no, what)); };
      if (line_no == 1) {
        if (line != "ply") fail("not a PLY file (the first line is not 'ply')");
        continue;
      }
      if (tok.empty()) continue;
      if (tok[0] == "comment" || tok[0] == "obj_info") continue;
      if (tok[0] == "end_header") break;
      if (tok[0] == "format") {
        if (tok.size() != 3) bad("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
        if (tok[1] == "ascii") format_ = Format::Ascii;
        else if (tok[1] == "binary_little_endian") format_ = Format::Little;
        else if (tok[1] == "binary_big_endian") format_ = Format::Big;
        else bad(fmt::format("unknown format '{:.40}'", tok[1]));
        have_format = true;
      } else if (tok[0] == "element") {
        uint64_t count = 0;
        if (tok.size() != 3) bad("expected 'element NAME COUNT'");
        auto [p, ec] = std::from_chars(tok[2].data(), tok[2].data() + tok[2].size(), count);
        if (ec != std::errc() || p != tok[2].data() + tok[2].size()) bad(fmt::format("'{:.40}' is not a count", tok[2]));
        if (elements_.size() >= 64) bad("more than 64 elements");
        elements_.push_back({std::string(tok[1]), count, {}});
      } else if (tok[0] == "property") {
        if (elements_.empty()) bad("a property before any element");
        Property prop;
        if (tok.size() == 5 && tok[1] == "list") {
          prop.list = true;
          if (!type_of(tok[2], prop.count_type) || !is_integer(prop.count_type))
            bad(fmt::format("'{:.40}' is not an integer type for a list length", tok[2]));
          if (!type_of(tok[3], prop.type)) bad(fmt::format("unknown type '{:.40}'", tok[3]));
          prop.name = tok[4];
        } else if (tok.size() == 3) {
          if (!type_of(tok[1], prop.type)) bad(fmt::format("unknown type '{:.40}'", tok[1]));
          prop.name = tok[2];
        } else {
          bad("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
        }
        if (elements_.back().properties.size() >= 256) bad("more than 256 properties in one element");
        elements_.back().properties.push_back(prop);
      } else {
        bad(fmt::format("unknown header keyword '{:.40}'", tok[0]));
      }
    }
    if (!have_format) fail("the header has no 'format' line");
  }

  // An element's instances cannot need fewer bytes than the data holds: at least 2 a
  // value in ASCII ("0 "), the fixed sizes and list lengths in binary.
  void check_count(const Element& e) const {
    uint64_t least = 0;
    for (const Property& p : e.properties)
      least += format_ == Format::Ascii ? 2 : size_of(p.list ? p.count_type : p.type);
    if (least == 0) {
      if (e.count > 0) fail(fmt::format("element '{:.40}' has no properties", e.name));
      return;
    }
    const uint64_t left = text_.size() - pos_;
    if (e.count > left / least + (format_ == Format::Ascii ? 1 : 0))
      fail(fmt::format("element '{:.40}' declares {} entries, more than the {} bytes left can hold", e.name, e.count,
                       left));
    if (e.name == "face" && e.count > limits::kMaxTriangles)
      fail(fmt::format("{} faces: more than the supported {} triangles", e.count, limits::kMaxTriangles));
    if (e.name == "vertex" && e.count > limits::kMaxVertices)
      fail(fmt::format("{} vertices: more than the supported {}", e.count, limits::kMaxVertices));
  }

  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }

  double value(Type t) {
    if (format_ == Format::Ascii) {
      skip_space();
      size_t end = pos_;
      while (end < text_.size() && !std::isspace(static_cast<unsigned char>(text_[end]))) ++end;
      if (end == pos_) fail("the data ends early");
      double v = 0;
      std::string_view tok(text_.data() + pos_, end - pos_);
      if (tok.size() > 1 && tok[0] == '+') tok.remove_prefix(1);
      auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (ec != std::errc() || p != tok.data() + tok.size())
        fail(fmt::format("'{:.40}' (at byte {}) is not a number", std::string_view(text_.data() + pos_, end - pos_), pos_));
      if (is_integer(t) && v != std::floor(v)) fail(fmt::format("'{:.40}' (at byte {}) is not an integer", tok, pos_));
      pos_ = end;
      return v;
    }
    const size_t n = size_of(t);
    if (text_.size() - pos_ < n) fail("the binary data ends early");
    unsigned char b[8];
    std::memcpy(b, text_.data() + pos_, n);
    pos_ += n;
    if ((format_ == Format::Big) == (std::endian::native == std::endian::little))
      for (size_t i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
    switch (t) {
      case Type::I8: return double(int8_t(b[0]));
      case Type::U8: return double(b[0]);
      case Type::I16: { int16_t x; std::memcpy(&x, b, 2); return x; }
      case Type::U16: { uint16_t x; std::memcpy(&x, b, 2); return x; }
      case Type::I32: { int32_t x; std::memcpy(&x, b, 4); return x; }
      case Type::U32: { uint32_t x; std::memcpy(&x, b, 4); return x; }
      case Type::F32: { float x; std::memcpy(&x, b, 4); return x; }
      case Type::F64: { double x; std::memcpy(&x, b, 8); return x; }
    }
    return 0;
  }

  void add_polygon(MeshData& mesh, const std::vector<uint32_t>& poly, uint64_t face) const {
    if (poly.size() < 3) fail(fmt::format("face {} has {} vertices (at least 3)", face, poly.size()));
    if (mesh.triangles.size() + poly.size() - 2 > limits::kMaxTriangles)
      fail(fmt::format("more than {} triangles: the supported maximum per scene", limits::kMaxTriangles));
    for (size_t k = 1; k + 1 < poly.size(); ++k) mesh.triangles.push_back({{poly[0], poly[k], poly[k + 1]}});
  }
};

}  // namespace

MeshData read_ply(const std::string& path, const std::string& text, const Losses& losses) {
  return PlyReader(path, text).read(losses);
}

}  // namespace pb::scene_io
