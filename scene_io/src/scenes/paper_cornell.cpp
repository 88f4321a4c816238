// The 2015 paper's Cornell box, exactly as ../shared/paper-scene.md gives it.
#include <cmath>

#include "pathbench/scene_io/scene_library.h"

namespace pb {

Scene make_paper_cornell() {
  Scene s;
  s.name = "paper-cornell";
  s.positions = {{-10, -10, 22}, {-10, -10, -10}, {-10, 10, -10}, {-10, 10, 22}, {10, -10, 22},  {10, -10, -10},
                 {10, 10, -10},  {10, 10, 22},    {-5, 9.9f, -8},  {-5, 9.9f, -2}, {5, 9.9f, -2}, {5, 9.9f, -8}};
  s.materials = {
      {{0.5f, 0, 0}, {0, 0, 0}},           // 0 red, left wall
      {{0.5f, 0.5f, 0.5f}, {0, 0, 0}},     // 1 white: back, ceiling, floor, front
      {{0, 0.5f, 0}, {0, 0, 0}},           // 2 green, right wall
      {{0, 0, 0}, {10, 10, 10}},           // 3 light: emits downwards, does not reflect
  };
  s.material_names = {"red", "white", "green", "light"};
  struct Part { Triangle a, b; uint32_t material; };
  const Part parts[] = {
      {{{0, 1, 2}}, {{0, 2, 3}}, 0},    // left wall
      {{{1, 5, 6}}, {{1, 6, 2}}, 1},    // back wall
      {{{5, 7, 6}}, {{5, 4, 7}}, 2},    // right wall
      {{{2, 7, 3}}, {{2, 6, 7}}, 1},    // ceiling
      {{{0, 5, 1}}, {{0, 4, 5}}, 1},    // floor
      {{{0, 7, 3}}, {{0, 4, 7}}, 1},    // front wall, behind the camera
      {{{10, 9, 8}}, {{11, 10, 8}}, 3}, // light, 10 x 6 at y = 9.9
  };
  for (const Part& p : parts) {
    s.triangles.push_back(p.a);
    s.triangles.push_back(p.b);
    s.material_ids.push_back(p.material);
    s.material_ids.push_back(p.material);
  }
  // Pinhole at (0, 0, 20) looking down -z; full field of view 2 atan(10.5 / 19).
  const float fov_deg = 2.0f * std::atan(10.5f / 19.0f) * 180.0f / kPi<float>;
  s.camera = Camera::look_at({0, 0, 20}, {0, 0, 0}, {0, 1, 0}, fov_deg);
  s.finalize();
  return s;
}

}  // namespace pb
