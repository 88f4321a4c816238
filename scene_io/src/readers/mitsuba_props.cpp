// Mitsuba 3 XML: reading a plugin's typed properties (float, integer, string, boolean,
// point, rgb, spectrum, transform), with <default> substitution, and naming whatever
// was not read.
#include <fmt/core.h>

#include <charconv>
#include <cmath>

#include "pathbench/common/errors.h"
#include "readers/mitsuba.h"

namespace pb::scene_io::mitsuba {

void Document::fail(const pugi::xml_node& at, const std::string& what) const {
  const std::string where = at ? fmt::format("{}: ", describe(at)) : std::string();
  throw InputError(fmt::format("{}: Mitsuba XML: {}{}", path, where, what));
}

std::string Document::describe(const pugi::xml_node& n) {
  std::string s = fmt::format("<{:.30}", n.name());
  for (const char* a : {"type", "name", "id"})
    if (n.attribute(a)) s += fmt::format(" {}=\"{:.40}\"", a, n.attribute(a).value());
  return s + ">";
}

std::string Document::attr(const pugi::xml_node& n, const char* name) const {
  const std::string v = n.attribute(name).value();
  // "$name" anywhere: replaced by the <default> of that name (one pass, no recursion).
  std::string out;
  for (size_t i = 0; i < v.size();) {
    if (v[i] != '$') {
      out += v[i++];
      continue;
    }
    size_t j = i + 1;
    while (j < v.size() && (std::isalnum(static_cast<unsigned char>(v[j])) || v[j] == '_')) ++j;
    const std::string key = v.substr(i + 1, j - i - 1);
    const auto it = defaults.find(key);
    if (it == defaults.end()) fail(n, fmt::format("'${:.40}' has no <default name=\"{:.40}\">", key, key));
    // "$a$a$a..." of a long default multiplies it: the text substituted for "$name"s
    // is bounded per document (a legitimate scene substitutes a few bytes at a time).
    if ((expanded += it->second.size()) > kMaxExpandedBytes)
      fail(n, fmt::format("the <default> values substituted for '$name's add up to more than {} bytes (the supported "
                          "maximum)", kMaxExpandedBytes));
    out += it->second;
    i = j;
  }
  return out;
}

std::vector<double> numbers(const Document& doc, const pugi::xml_node& at, std::string_view text) {
  std::vector<double> out;
  for (size_t i = 0; i < text.size();) {
    while (i < text.size() && (text[i] == ',' || std::isspace(static_cast<unsigned char>(text[i])))) ++i;
    size_t j = i;
    while (j < text.size() && text[j] != ',' && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
    if (j == i) break;
    double v = 0;
    const char* b = text.data() + i + (text[i] == '+' ? 1 : 0);
    auto [p, ec] = std::from_chars(b, text.data() + j, v);
    if (ec != std::errc() || p != text.data() + j || !std::isfinite(v))
      doc.fail(at, fmt::format("'{:.40}' is not a finite number", std::string(text.substr(i, j - i))));
    out.push_back(v);
    if (out.size() > 64) doc.fail(at, "more than 64 numbers in one value");
    i = j;
  }
  return out;
}

Props::Props(const Document& doc, pugi::xml_node plugin) : doc_(doc), plugin_(plugin) {
  for (pugi::xml_node c : plugin.children()) {
    if (c.type() != pugi::node_element || !c.attribute("name")) continue;
    const std::string tag = c.name();
    if (tag == "ref" || tag == "bsdf" || tag == "emitter" || tag == "shape" || tag == "texture" || tag == "sampler" ||
        tag == "film" || tag == "rfilter")
      continue;  // plugins (read as children), not values
    if (!by_name_.emplace(c.attribute("name").value(), c).second)
      doc.fail(c, "a property of this name is given twice");
  }
}

pugi::xml_node Props::take(const std::string& name) {
  const auto it = by_name_.find(name);
  if (it == by_name_.end()) return {};
  used_.insert(name);
  return it->second;
}

double Props::number(const std::string& name, double fallback) {
  const pugi::xml_node n = take(name);
  if (!n) return fallback;
  const std::string tag = n.name();
  if (tag != "float" && tag != "integer") doc_.fail(n, "expected a <float> or <integer>");
  const auto v = numbers(doc_, n, doc_.attr(n, "value"));
  if (v.size() != 1) doc_.fail(n, "expected one number in value");
  return v[0];
}

int Props::integer(const std::string& name, int fallback) {
  const pugi::xml_node n = take(name);
  if (!n) return fallback;
  const auto v = numbers(doc_, n, doc_.attr(n, "value"));
  if (std::string(n.name()) != "integer" || v.size() != 1 || v[0] != std::floor(v[0]) || std::fabs(v[0]) > 1e9)
    doc_.fail(n, "expected an <integer> with a whole number");
  return int(v[0]);
}

std::string Props::string(const std::string& name, const std::string& fallback) {
  const pugi::xml_node n = take(name);
  if (!n) return fallback;
  if (std::string(n.name()) != "string") doc_.fail(n, "expected a <string>");
  return doc_.attr(n, "value");
}

bool Props::boolean(const std::string& name, bool fallback) {
  const pugi::xml_node n = take(name);
  if (!n) return fallback;
  const std::string v = doc_.attr(n, "value");
  if (std::string(n.name()) != "boolean" || (v != "true" && v != "false"))
    doc_.fail(n, "expected a <boolean> with value true or false");
  return v == "true";
}

Vec3f Props::point(const std::string& name, Vec3f fallback) {
  const pugi::xml_node n = take(name);
  if (!n) return fallback;
  if (n.attribute("value")) {
    const auto v = numbers(doc_, n, doc_.attr(n, "value"));
    if (v.size() != 3) doc_.fail(n, "expected 3 numbers in value");
    return {float(v[0]), float(v[1]), float(v[2])};
  }
  Vec3f p{0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    const char key[2] = {"xyz"[a], 0};
    if (!n.attribute(key)) continue;
    const auto v = numbers(doc_, n, doc_.attr(n, key));
    if (v.size() != 1) doc_.fail(n, fmt::format("expected one number in {}", key));
    p[a] = float(v[0]);
  }
  return p;
}

Vec3f Props::colour(const std::string& name, Vec3f fallback) {
  for (pugi::xml_node t : plugin_.children("texture"))
    if (name == t.attribute("name").value()) {
      doc_.losses->report(doc_.path, fmt::format("texture '{:.40}' of type '{:.20}' (a constant colour is used)", name,
                                                 t.attribute("type").value()));
      return fallback;
    }
  const pugi::xml_node n = take(name);
  if (!n) return fallback;
  const std::string tag = n.name();
  const std::string value = doc_.attr(n, "value");
  if (tag == "spectrum" && value.find(':') != std::string::npos) {
    // "400:0.1, 500:0.2, ...": the mean of the values, as a grey. A view moves along
    // the list: copying the rest after each entry made a long list quadratic.
    doc_.losses->report(doc_.path, fmt::format("spectrum '{:.40}' given by wavelength (its mean is used)", name));
    double sum = 0;
    uint64_t count = 0;
    std::string_view rest = value;
    for (size_t c; (c = rest.find(':')) != std::string_view::npos;) {
      const size_t end = rest.find_first_of(", ", c);
      const auto v = numbers(doc_, n, rest.substr(c + 1, end == std::string_view::npos ? std::string_view::npos : end - c - 1));
      if (v.size() == 1) sum += v[0], ++count;
      rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    }
    const float g = count ? float(sum / count) : 0.0f;
    return {g, g, g};
  }
  if (tag != "rgb" && tag != "spectrum" && tag != "float") doc_.fail(n, "expected an <rgb>, <spectrum> or <float> colour");
  const auto v = numbers(doc_, n, value);
  if (v.size() == 1) return {float(v[0]), float(v[0]), float(v[0])};
  if (v.size() == 3 && tag == "rgb") return {float(v[0]), float(v[1]), float(v[2])};
  doc_.fail(n, "expected one number, or three for <rgb>");
}

Affine Props::transform(const std::string& name) {
  const pugi::xml_node t = take(name);
  if (!t) return Affine();
  if (std::string(t.name()) != "transform") doc_.fail(t, "expected a <transform>");
  Affine a;
  for (pugi::xml_node op : t.children()) {
    if (op.type() != pugi::node_element) continue;
    const std::string kind = op.name();
    auto xyz = [&](double fallback) {
      double v[3] = {fallback, fallback, fallback};
      if (op.attribute("value")) {
        const auto n = numbers(doc_, op, doc_.attr(op, "value"));
        if (n.size() == 1 && kind == "scale") return Vec3<double>{n[0], n[0], n[0]};
        if (n.size() != 3) doc_.fail(op, "expected 3 numbers in value");
        return Vec3<double>{n[0], n[1], n[2]};
      }
      for (int i = 0; i < 3; ++i) {
        const char key[2] = {"xyz"[i], 0};
        if (!op.attribute(key)) continue;
        const auto n = numbers(doc_, op, doc_.attr(op, key));
        if (n.size() != 1) doc_.fail(op, fmt::format("expected one number in {}", key));
        v[i] = n[0];
      }
      return Vec3<double>{v[0], v[1], v[2]};
    };
    auto vec = [&](const char* key) {
      const auto n = numbers(doc_, op, doc_.attr(op, key));
      if (n.size() != 3) doc_.fail(op, fmt::format("{} needs 3 numbers", key));
      return Vec3<double>{n[0], n[1], n[2]};
    };
    Affine step;
    if (kind == "translate") {
      const auto d = xyz(0);
      step = Affine::translate(d.x, d.y, d.z);
    } else if (kind == "scale") {
      const auto s = xyz(1);
      step = Affine::scale(s.x, s.y, s.z);
    } else if (kind == "rotate") {
      const auto axis = xyz(0);
      const auto angle = numbers(doc_, op, doc_.attr(op, "angle"));
      if (angle.size() != 1) doc_.fail(op, "needs an angle (degrees)");
      if (axis.x == 0 && axis.y == 0 && axis.z == 0) doc_.fail(op, "the rotation axis is zero");
      step = Affine::rotate(axis.x, axis.y, axis.z, angle[0]);
    } else if (kind == "matrix") {
      const auto m = numbers(doc_, op, doc_.attr(op, "value"));
      if (m.size() != 16 && m.size() != 9) doc_.fail(op, "expected 16 numbers (4x4, row by row) or 9 (3x3)");
      const int cols = m.size() == 16 ? 4 : 3;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < cols; ++c) step.m[r][c] = m[size_t(r * cols + c)];
      if (cols == 4 && !(m[12] == 0 && m[13] == 0 && m[14] == 0 && m[15] == 1))
        doc_.fail(op, "the last row must be 0 0 0 1 (projective transforms are not supported)");
    } else if (kind == "lookat") {
      const auto o = vec("origin"), target = vec("target");
      const auto up = op.attribute("up") ? vec("up") : Vec3<double>{0, 1, 0};
      const Vec3<double> d = target - o;
      if (length(d) == 0) doc_.fail(op, "origin and target are the same point");
      const Vec3<double> dir = normalize(d);
      Vec3<double> left = cross(up, dir);
      if (length(left) == 0) doc_.fail(op, "up is zero or parallel to the view direction");
      left = normalize(left);
      const Vec3<double> new_up = cross(dir, left);
      const Vec3<double> cols[4] = {left, new_up, dir, o};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) step.m[r][c] = cols[c][r];
    } else {
      doc_.fail(op, "unknown transform operation (translate, rotate, scale, matrix, lookat)");
    }
    a = step * a;
  }
  if (!a.finite()) doc_.fail(t, "the transform is not finite");
  return a;
}

std::vector<pugi::xml_node> Props::children(const char* tag) const {
  std::vector<pugi::xml_node> out;
  for (pugi::xml_node c : plugin_.children())
    if (c.type() == pugi::node_element && std::string(c.name()) == tag) out.push_back(c);
  return out;
}

void Props::finish(const std::set<std::string>& handled) const {
  const std::string what = Document::describe(plugin_);
  for (const auto& [name, n] : by_name_)
    if (!used_.count(name)) doc_.losses->report(doc_.path, fmt::format("{} property '{:.40}'", what, name));
  for (pugi::xml_node c : plugin_.children()) {
    if (c.type() != pugi::node_element || c.attribute("name")) continue;
    if (!handled.count(c.name())) doc_.losses->report(doc_.path, fmt::format("{} in {}", Document::describe(c), what));
  }
}

}  // namespace pb::scene_io::mitsuba
