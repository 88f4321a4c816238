// OFF meshes (Object File Format, as Geomview and CGAL write them: the scanned meshes of
// Debian's libcgal-demo): a header "OFF" (or COFF, NOFF, STOFF... whose extra per-vertex
// values are named as not modelled), the counts "vertices faces edges", then one vertex
// "x y z" and one face "n i1 ... in" per line; '#' starts a comment. Faces of more than
// three corners are fan-triangulated, as the PLY reader does. Hostile input is one
// InputError naming the file and the line: truncated data, counts the bytes left cannot
// hold, NaN or infinite coordinates, out-of-range indices, faces of fewer than 3
// corners, the binary and n-dimensional variants.
#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <string_view>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "readers/readers.h"

namespace pb::scene_io {

namespace {

class OffReader {
 public:
  OffReader(const std::string& path, const std::string& text) : path_(path), text_(text) {}

  MeshData read(const Losses& losses) {
    std::vector<std::string_view> tok;
    if (!next_line(tok)) fail("the file is empty (expected the header 'OFF')");
    read_keyword(tok.front(), losses);
    if (tok.size() > 1 && tok[1] == "BINARY") bad("binary OFF is not read (convert it to ASCII OFF or to PLY)");
    tok.erase(tok.begin());  // "OFF 8 12 0" on one line is allowed
    if (tok.empty() && !next_line(tok)) fail("the file ends before the counts line 'VERTICES FACES EDGES'");
    if (tok.size() < 2 || tok.size() > 3) bad("expected the counts 'VERTICES FACES EDGES'");
    const uint64_t nv = count(tok[0], "vertex count"), nf = count(tok[1], "face count");
    if (tok.size() == 3) count(tok[2], "edge count");  // checked, unused (often 0)
    // Every vertex needs at least "0 0 0\n" (6 bytes), every face "3 0 0 0\n" (8): a small
    // file cannot ask for gigabytes.
    const uint64_t left = text_.size() - pos_;
    if (nv > left / 6 + 1 || nf > left / 8 + 1 || nv * 6 + nf * 8 > left + 8)
      bad(fmt::format("{} vertices and {} faces: more than the {} bytes left can hold (a truncated file, or wrong "
                      "counts)", nv, nf, left));
    if (nf > limits::kMaxTriangles)
      bad(fmt::format("{} faces: more than the supported {} triangles", nf, limits::kMaxTriangles));
    if (nv > uint64_t(UINT32_MAX)) bad(fmt::format("{} vertices: more than indices can address", nv));

    MeshData mesh;
    mesh.positions.reserve(nv);
    for (uint64_t i = 0; i < nv; ++i) {
      if (!next_line(tok)) fail(fmt::format("the file ends after {} of its {} vertices (truncated?)", i, nv));
      if (tok.size() < 3) bad(fmt::format("vertex {}: expected 'x y z', got {} value(s)", i, tok.size()));
      if (tok.size() > 3) losses.report(path_, "values after x y z on vertex lines (colours, normals, texture coordinates)");
      Vec3f p;
      for (int a = 0; a < 3; ++a) p[a] = float(number(tok[size_t(a)], fmt::format("vertex {}", i)));
      if (!is_finite(p)) bad(fmt::format("vertex {} has a NaN or infinite coordinate (or one too large for a float)", i));
      mesh.positions.push_back(p);
    }
    mesh.triangles.reserve(nf);
    for (uint64_t f = 0; f < nf; ++f) {
      if (!next_line(tok)) fail(fmt::format("the file ends after {} of its {} faces (truncated?)", f, nf));
      const uint64_t n = count(tok[0], fmt::format("face {}: corner count", f).c_str());
      if (n < 3) bad(fmt::format("face {} has {} corners (at least 3)", f, n));
      if (tok.size() < n + 1) bad(fmt::format("face {}: {} corners announced, {} given", f, n, tok.size() - 1));
      if (tok.size() > n + 1) losses.report(path_, "values after a face's corners (face colours)");
      if (mesh.triangles.size() + n - 2 > limits::kMaxTriangles)
        bad(fmt::format("more than {} triangles: the supported maximum per scene", limits::kMaxTriangles));
      uint32_t first = 0, prev = 0;
      for (uint64_t k = 0; k < n; ++k) {
        const uint64_t v = count(tok[k + 1], fmt::format("face {}: corner {}", f, k).c_str());
        if (v >= nv) bad(fmt::format("face {} refers to vertex {}, but the file has only {} vertices (0 to {})", f, v,
                                     nv, int64_t(nv) - 1));
        if (k == 0) first = uint32_t(v);
        else if (k >= 2) mesh.triangles.push_back({{first, prev, uint32_t(v)}});
        prev = uint32_t(v);
      }
    }
    if (next_line(tok)) bad("data after the last face (more lines than the counts say)");
    if (mesh.triangles.empty()) fail("the file has no faces");
    mesh.material_ids.assign(mesh.triangles.size(), -1);
    return mesh;
  }

 private:
  const std::string& path_;
  const std::string& text_;
  size_t pos_ = 0;
  size_t line_no_ = 0;

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(fmt::format("{}: malformed OFF: {}", path_, what));
  }
  [[noreturn]] void bad(const std::string& what) const { fail(fmt::format("line {}: {}", line_no_, what)); }

  // The next line with something on it (comments and blank lines skipped), split at
  // white space; false at the end of the text.
  bool next_line(std::vector<std::string_view>& tok) {
    tok.clear();
    while (pos_ < text_.size()) {
      size_t end = text_.find('\n', pos_);
      if (end == std::string::npos) end = text_.size();
      std::string_view line(text_.data() + pos_, end - pos_);
      pos_ = end + (end < text_.size() ? 1 : 0);
      ++line_no_;
      if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
      for (size_t i = 0; i < line.size();) {
        while (i < line.size() && is_space(line[i])) ++i;
        size_t j = i;
        while (j < line.size() && !is_space(line[j])) ++j;
        if (j > i) tok.push_back(line.substr(i, j - i));
        i = j;
      }
      if (!tok.empty()) return true;
    }
    return false;
  }
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

  // OFF, or its variants with per-vertex extras ([ST][C][N][4][n]OFF): those extras are
  // named as lost; 4OFF / nOFF (other dimensions) and binary OFF are refused.
  void read_keyword(std::string_view k, const Losses& losses) {
    const bool off = k.size() >= 3 && k.substr(k.size() - 3) == "OFF";
    if (!off) {
      if (k.size() > 0 && (std::isdigit(static_cast<unsigned char>(k[0])) || k[0] == '-'))
        bad("the header 'OFF' is missing (the file starts with a number)");
      bad(fmt::format("not an OFF file (the first word is '{:.40}', expected 'OFF')", k));
    }
    std::string_view prefix = k.substr(0, k.size() - 3);
    if (prefix.find('4') != std::string_view::npos || prefix.find('n') != std::string_view::npos)
      bad(fmt::format("'{:.40}': only 3-dimensional OFF files are read", k));
    for (char c : prefix)
      if (c != 'S' && c != 'T' && c != 'C' && c != 'N') bad(fmt::format("'{:.40}' is not an OFF header", k));
    if (!prefix.empty()) losses.report(path_, fmt::format("per-vertex data of {} (colours, normals, texture coordinates)", k));
  }

  uint64_t count(std::string_view t, const char* what) const {
    uint64_t v = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec == std::errc::result_out_of_range) bad(fmt::format("{} '{:.40}' is too large", what, t));
    if (ec != std::errc() || p != t.data() + t.size())
      bad(fmt::format("{}: '{:.40}' is not a whole number >= 0", what, t));
    return v;
  }
  uint64_t count(std::string_view t, const std::string& what) const { return count(t, what.c_str()); }

  double number(std::string_view t, const std::string& what) const {
    if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
    double v = 0;
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec == std::errc::result_out_of_range) bad(fmt::format("{}: '{:.40}' is out of range for a float", what, t));
    if (ec != std::errc() || p != t.data() + t.size()) bad(fmt::format("{}: '{:.40}' is not a number", what, t));
    return v;
  }
};

}  // namespace

MeshData read_off(const std::string& path, const std::string& text, const Losses& losses) {
  return OffReader(path, text).read(losses);
}

}  // namespace pb::scene_io
