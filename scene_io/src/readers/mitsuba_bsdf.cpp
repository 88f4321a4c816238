// Mitsuba 3 BSDFs -> pathbench materials: diffuse, twosided, conductor (material
// "none": a mirror), roughconductor (GGX), dielectric. Each as Mitsuba defines it
// (../mitsuba_export.cpp maps the other way); anything else named as not modelled.
// Also the built-in shapes (rectangle, cube, sphere) as meshes.
#include <fmt/core.h>

#include <cmath>

#include "pathbench/common/errors.h"
#include "readers/mitsuba.h"
#include "scenes/builder.h"

namespace pb::scene_io::mitsuba {

namespace {

// Mitsuba's named indices of refraction (its documentation's table).
double named_ior(const Document& doc, const pugi::xml_node& at, Props& p, const char* name, double fallback) {
  static const std::pair<const char*, double> kIor[] = {
      {"vacuum", 1.0},        {"helium", 1.00004},   {"hydrogen", 1.00013},  {"air", 1.00028},
      {"carbon dioxide", 1.00045}, {"water", 1.3330}, {"acetone", 1.36},     {"ethanol", 1.361},
      {"carbon tetrachloride", 1.461}, {"glycerol", 1.4729}, {"benzene", 1.501}, {"silicone oil", 1.52045},
      {"bromine", 1.661},     {"water ice", 1.31},   {"fused quartz", 1.458}, {"pyrex", 1.470},
      {"acrylic glass", 1.49}, {"polypropylene", 1.49}, {"bk7", 1.5046},    {"sodium chloride", 1.544},
      {"amber", 1.55},        {"pet", 1.5750},       {"diamond", 2.419}};
  if (!p.has(name)) return fallback;
  const pugi::xml_node n = p.node().find_child_by_attribute("name", name);
  if (std::string(n.name()) != "string") return p.number(name, fallback);
  const std::string v = p.string(name, "");
  for (const auto& [k, ior] : kIor)
    if (v == k) return ior;
  doc.fail(at, fmt::format("{}: unknown index of refraction '{:.40}'", name, v));
}

Material conductor(const Document& doc, Props& p, bool rough) {
  Material m{};
  const std::string what = Document::describe(p.node());
  const std::string preset = p.string("material", "none");
  if (preset != "none" || p.has("eta") || p.has("k"))
    doc.losses->report(doc.path, fmt::format("{}: a metal's complex index of refraction (material '{:.20}', eta, k): "
                                             "Fresnel reflectance 1 (specular_reflectance only)", what, preset));
  (void)p.colour("eta", {}), (void)p.colour("k", {});
  m.albedo = p.colour("specular_reflectance", {1, 1, 1});
  if (!rough) {
    m.kind = MaterialKind::Mirror;
    return m;
  }
  m.kind = MaterialKind::RoughConductor;
  const std::string dist = p.string("distribution", "beckmann");
  if (dist != "ggx")
    doc.losses->report(doc.path, fmt::format("{}: microfacet distribution '{:.20}' (rendered as GGX)", what, dist));
  double alpha = p.number("alpha", 0.1);
  if (p.has("alpha_u") || p.has("alpha_v")) {
    const double u = p.number("alpha_u", 0.1), v = p.number("alpha_v", 0.1);
    if (u != v) doc.losses->report(doc.path, fmt::format("{}: anisotropic roughness (their mean is used)", what));
    alpha = 0.5 * (u + v);
  }
  p.boolean("sample_visible", true);
  m.alpha = float(alpha);
  if (m.alpha < Material::kMinAlpha) m.kind = MaterialKind::Mirror;
  return m;
}

}  // namespace

Material read_bsdf(const Document& doc, pugi::xml_node bsdf, int depth) {
  if (depth > 16) doc.fail(bsdf, "BSDFs nested more than 16 deep (a cycle of <ref>s?)");
  if (std::string(bsdf.name()) == "ref") {
    const auto it = doc.ids.find(doc.attr(bsdf, "id"));
    if (it == doc.ids.end()) doc.fail(bsdf, "no element has this id");
    return read_bsdf(doc, it->second, depth + 1);
  }
  if (std::string(bsdf.name()) != "bsdf") doc.fail(bsdf, "expected a <bsdf>");
  const std::string type = doc.attr(bsdf, "type");
  Props p(doc, bsdf);
  Material m{};
  auto nested = [&]() {
    std::vector<pugi::xml_node> inner = p.children("bsdf");
    for (pugi::xml_node r : p.children("ref")) inner.push_back(r);
    if (inner.empty()) doc.fail(bsdf, "needs a nested <bsdf>");
    if (inner.size() > 1)
      doc.losses->report(doc.path, fmt::format("{}: a different BSDF on each side (the first is used)", Document::describe(bsdf)));
    return read_bsdf(doc, inner[0], depth + 1);
  };
  if (type == "twosided") {
    m = nested();  // pathbench's BSDFs are two-sided already
    p.finish({"bsdf", "ref"});
    return m;
  }
  if (type == "bumpmap" || type == "normalmap" || type == "mask") {
    doc.losses->report(doc.path, fmt::format("bsdf '{}' (the nested BSDF is used alone)", type));
    return nested();
  }
  if (type == "diffuse") {
    m.albedo = p.colour("reflectance", {0.5f, 0.5f, 0.5f});
  } else if (type == "conductor" || type == "roughconductor") {
    m = conductor(doc, p, type == "roughconductor");
  } else if (type == "dielectric") {
    m.kind = MaterialKind::Dielectric;
    const double inside = named_ior(doc, bsdf, p, "int_ior", 1.5046), outside = named_ior(doc, bsdf, p, "ext_ior", 1.000277);
    m.ior = float(inside / outside);
    const Vec3f r = p.colour("specular_reflectance", {1, 1, 1}), t = p.colour("specular_transmittance", {1, 1, 1});
    if (!(r.x == t.x && r.y == t.y && r.z == t.z))
      doc.losses->report(doc.path, fmt::format("{}: different specular_reflectance and specular_transmittance (the "
                                               "transmittance tints both)", Document::describe(bsdf)));
    m.albedo = t;
  } else {
    // Another BSDF: a diffuse stand-in of its diffuse colour, named as not modelled.
    doc.losses->report(doc.path, fmt::format("bsdf '{:.30}' (a diffuse stand-in is used)", type));
    for (const char* k : {"diffuse_reflectance", "base_color", "reflectance"})
      if (p.has(k)) {
        m.albedo = p.colour(k, {0.5f, 0.5f, 0.5f});
        return m;
      }
    m.albedo = {0.5f, 0.5f, 0.5f};
    return m;
  }
  p.finish();
  return m;
}

MeshData rectangle_mesh() {
  MeshData m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  m.triangles = {{{0, 1, 2}}, {{0, 2, 3}}};
  return m;
}

MeshData cube_mesh() {
  Scene s;  // the builder's quads, wound to face out
  using scenes::add_vertex;
  for (int i = 0; i < 8; ++i) add_vertex(s, {i & 1 ? 1.f : -1.f, i & 2 ? 1.f : -1.f, i & 4 ? 1.f : -1.f});
  const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) scenes::add_quad(s, f[0], f[1], f[2], f[3], 0);
  return {s.positions, s.triangles, {}, {}, {}};
}

MeshData sphere_mesh(Vec3f centre, float radius) {
  // The unit sphere is tessellated once; each sphere scales and moves it (the same
  // floats as tessellating it there: centre + unit * radius).
  static const MeshData unit = [] {
    Scene s;
    scenes::append_uv_sphere(s, {0, 0, 0}, 1.0f, 64, 32, 0);
    return MeshData{s.positions, s.triangles, {}, {}, {}};
  }();
  static_assert(2 * 64 * 32 == kSphereTriangles);
  MeshData m{{}, unit.triangles, {}, {}, {}};
  m.positions.reserve(unit.positions.size());
  for (const Vec3f& p : unit.positions) m.positions.push_back(centre + p * radius);
  return m;
}

}  // namespace pb::scene_io::mitsuba
