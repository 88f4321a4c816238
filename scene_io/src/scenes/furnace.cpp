// White furnace: a closed cube whose every wall reflects `albedo` and emits
// `emission`. Every path sees the same radiance, known in closed form:
// Le (1 + a + ... + a^k) after k bounces, Le / (1 - a) unbounded.
#include "pathbench/scene_io/scene_library.h"

namespace pb {

Scene make_furnace(float albedo, float emission) {
  Scene s;
  s.name = "furnace";
  s.positions = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                 {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  // Faces wound so every normal points into the cube (emission is one-sided).
  const uint32_t quads[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 5, 6, 2}};
  for (const auto& q : quads) {
    s.triangles.push_back({{q[0], q[1], q[2]}});
    s.triangles.push_back({{q[0], q[2], q[3]}});
  }
  s.material_ids.assign(s.triangles.size(), 0);
  s.materials = {{{albedo, albedo, albedo}, {emission, emission, emission}}};
  s.material_names = {"furnace"};
  s.camera = Camera::look_at({0, 0, 0.5f}, {0, 0, -1}, {0, 1, 0}, 60.0f);
  s.finalize();
  return s;
}

}  // namespace pb
