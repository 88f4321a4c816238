// `cornell-box`: the Cornell box as Cornell University's Program of Computer Graphics
// published it ("Cornell Box Data", graphics.cornell.edu/online/box/data.html):
// geometry in millimetres, the camera at (278, 273, -800) looking along +z with a
// 35 mm lens on a 25 mm square film. The published reflectances are spectra; the
// albedos here are the usual RGB approximations of them, and the light's radiance
// the usual RGB (17, 12, 4). The room is open at z = 0, towards the camera.
//
// `cornell-box:VARIANT`: the same room with other materials (bsdf/):
//   mirror   the tall block a mirror
//   glass    the short block glass (ior 1.5)
//   spheres  no blocks: a mirror sphere (back left) and a glass sphere (front right),
//            as in Jensen's photon-mapping renders (icospheres of 5120 flat triangles)
//   ggx      the tall block rough copper-coloured metal (GGX, alpha 0.2)
#include <fmt/core.h>

#include <cmath>
#include <string>

#include "builder.h"
#include "pathbench/common/errors.h"
#include "pathbench/scene_io/scene_library.h"

namespace pb {

namespace {

struct Room {
  Scene s;
  uint32_t white;
};

// Walls, floor, ceiling and light; no blocks.
Room cornell_room(std::string name) {
  using scenes::add_material;
  using scenes::add_quad;
  using scenes::add_vertex;
  Room r;
  Scene& s = r.s;
  s.name = std::move(name);
  r.white = add_material(s, "white", {0.75f, 0.75f, 0.75f});
  const uint32_t white = r.white;
  const uint32_t red = add_material(s, "red", {0.63f, 0.065f, 0.05f});
  const uint32_t green = add_material(s, "green", {0.14f, 0.45f, 0.091f});
  const uint32_t light = add_material(s, "light", {0, 0, 0}, {17, 12, 4});

  // A published quadrilateral (the data lists quads; the walls are not quite planar
  // or rectangular, as in the measured box).
  auto quad = [&](Vec3f a, Vec3f b, Vec3f c, Vec3f d, uint32_t m) {
    add_quad(s, add_vertex(s, a), add_vertex(s, b), add_vertex(s, c), add_vertex(s, d), m);
  };
  quad({552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f}, white);              // floor
  quad({549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {556, 548.8f, 559.2f}, white);  // back wall
  quad({0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f}, green);              // right wall
  quad({552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556, 548.8f, 559.2f}, {556, 548.8f, 0}, red);  // left wall

  // The light fills the opening in the ceiling; its normal, cross(v1 - v0, v2 - v0),
  // points down. The ceiling is the ring of four quads around it, sharing its
  // corners, so there is neither overlap nor gap.
  const uint32_t l0 = add_vertex(s, {343, 548.8f, 227}), l1 = add_vertex(s, {343, 548.8f, 332}),
                 l2 = add_vertex(s, {213, 548.8f, 332}), l3 = add_vertex(s, {213, 548.8f, 227});
  add_quad(s, l0, l1, l2, l3, light);
  const uint32_t c0 = add_vertex(s, {556, 548.8f, 0}), c1 = add_vertex(s, {556, 548.8f, 559.2f}),
                 c2 = add_vertex(s, {0, 548.8f, 559.2f}), c3 = add_vertex(s, {0, 548.8f, 0});
  add_quad(s, c0, c1, l1, l0, white);
  add_quad(s, c1, c2, l2, l1, white);
  add_quad(s, c2, c3, l3, l2, white);
  add_quad(s, c3, c0, l0, l3, white);

  // Focal length 0.035 m, film 0.025 m: vertical field of view 2 atan(12.5 / 35).
  const float fov_deg = 2.0f * std::atan(12.5f / 35.0f) * 180.0f / kPi<float>;
  s.camera = Camera::look_at({278, 273, -800}, {278, 273, 0}, {0, 1, 0}, fov_deg);
  return r;
}

void quad(Scene& s, Vec3f a, Vec3f b, Vec3f c, Vec3f d, uint32_t m) {
  using scenes::add_vertex;
  scenes::add_quad(s, add_vertex(s, a), add_vertex(s, b), add_vertex(s, c), add_vertex(s, d), m);
}

// Short block: top, then four sides (outward normals).
void short_block(Scene& s, uint32_t m) {
  quad(s, {130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}, m);
  quad(s, {290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}, m);
  quad(s, {130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}, m);
  quad(s, {82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}, m);
  quad(s, {240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}, m);
}

void tall_block(Scene& s, uint32_t m) {
  quad(s, {423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}, m);
  quad(s, {423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}, m);
  quad(s, {472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}, m);
  quad(s, {314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}, m);
  quad(s, {265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}, m);
}

Material mirror() { return {{0.95f, 0.95f, 0.95f}, {0, 0, 0}, MaterialKind::Mirror}; }
Material glass() {
  Material m{{1, 1, 1}, {0, 0, 0}, MaterialKind::Dielectric};
  m.ior = 1.5f;
  return m;
}

}  // namespace

Scene make_cornell_box() {
  Room r = cornell_room("cornell-box");
  short_block(r.s, r.white);
  tall_block(r.s, r.white);
  r.s.finalize();
  return r.s;
}

const std::vector<std::string>& cornell_box_variants() {
  static const std::vector<std::string> v = {"mirror", "glass", "spheres", "ggx"};
  return v;
}

Scene make_cornell_box(const std::string& variant) {
  if (variant.empty()) return make_cornell_box();
  Room r = cornell_room("cornell-box:" + variant);
  Scene& s = r.s;
  using scenes::append_material;
  if (variant == "mirror") {
    short_block(s, r.white);
    tall_block(s, append_material(s, "mirror", mirror()));
  } else if (variant == "glass") {
    short_block(s, append_material(s, "glass", glass()));
    tall_block(s, r.white);
  } else if (variant == "spheres") {
    scenes::append_icosphere(s, {380, 100, 360}, 100, 4, append_material(s, "mirror", mirror()));
    scenes::append_icosphere(s, {175, 100, 190}, 100, 4, append_material(s, "glass", glass()));
  } else if (variant == "ggx") {
    Material copper{{0.95f, 0.64f, 0.54f}, {0, 0, 0}, MaterialKind::RoughConductor};
    copper.alpha = 0.2f;
    short_block(s, r.white);
    tall_block(s, append_material(s, "copper", copper));
  } else {
    std::string known;
    for (const std::string& v : cornell_box_variants()) known += (known.empty() ? "" : ", ") + v;
    throw InputError(fmt::format("scene 'cornell-box:{}': unknown variant (expected one of: {})", variant, known));
  }
  s.finalize();
  return s;
}

}  // namespace pb
