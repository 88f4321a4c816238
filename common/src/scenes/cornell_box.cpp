// `cornell-box`: the Cornell box as Cornell University's Program of Computer Graphics
// published it ("Cornell Box Data", graphics.cornell.edu/online/box/data.html):
// geometry in millimetres, the camera at (278, 273, -800) looking along +z with a
// 35 mm lens on a 25 mm square film. The published reflectances are spectra; the
// albedos here are the usual RGB approximations of them, and the light's radiance
// the usual RGB (17, 12, 4). The room is open at z = 0, towards the camera.
#include <cmath>

#include "builder.h"
#include "pathbench/common/scene_library.h"

namespace pb {

Scene make_cornell_box() {
  using scenes::add_material;
  using scenes::add_quad;
  using scenes::add_vertex;
  Scene s;
  s.name = "cornell-box";
  const uint32_t white = add_material(s, "white", {0.75f, 0.75f, 0.75f});
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

  // Short block: top, then four sides.
  quad({130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114}, white);
  quad({290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272}, white);
  quad({130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114}, white);
  quad({82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65}, white);
  quad({240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225}, white);
  // Tall block.
  quad({423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406}, white);
  quad({423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406}, white);
  quad({472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456}, white);
  quad({314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296}, white);
  quad({265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247}, white);

  // Focal length 0.035 m, film 0.025 m: vertical field of view 2 atan(12.5 / 35).
  const float fov_deg = 2.0f * std::atan(12.5f / 35.0f) * 180.0f / kPi<float>;
  s.camera = Camera::look_at({278, 273, -800}, {278, 273, 0}, {0, 1, 0}, fov_deg);
  s.finalize();
  return s;
}

}  // namespace pb
