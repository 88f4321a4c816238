#pragma once
// Where scenes come from: built-in names (with parameters after a colon) and files.
#include <cstdint>
#include <string>
#include <vector>

#include "pathbench/common/scene.h"

namespace pb {

struct BuiltinSceneInfo {
  std::string name;         // e.g. "paper-cornell-ico:L"
  std::string description;
};
const std::vector<BuiltinSceneInfo>& builtin_scenes();

// "paper-cornell", "furnace:0.5", a .json scene file or a bare .obj mesh. The result
// is finalized. Throws InputError naming the scene or file and what is wrong.
Scene load_scene(const std::string& name_or_path);

// Built-ins, also callable directly.
Scene make_paper_cornell();
// Closed cube, every wall albedo `albedo` and emission `emission` (white furnace).
Scene make_furnace(float albedo, float emission);
// The Cornell box from Cornell University's published data (millimetres; camera at
// (278, 273, -800) looking along +z, 39.3 degree field of view).
Scene make_cornell_box();
// The same room with mirror, glass or rough-metal objects: `variant` is one of
// cornell_box_variants() ("mirror", "glass", "spheres", "ggx"); "" is make_cornell_box().
Scene make_cornell_box(const std::string& variant);
const std::vector<std::string>& cornell_box_variants();
// make_paper_cornell() plus an icosphere of subdivision `level` (0..10: 20 * 4^level
// triangles), radius 5, centre (0, -4, -4), albedo 0.5.
Scene make_paper_cornell_ico(int level);
// make_paper_cornell() plus a tessellated sphere (radius 5, centre (0, -4, -4), albedo
// 0.5): about `triangles` in all (the sphere takes the remainder; at least the box's 14).
Scene make_scaling(uint64_t triangles);

// Scene files (scene_file.cpp).
Scene load_scene_json(const std::string& path);
Scene load_scene_obj(const std::string& path);

}  // namespace pb
