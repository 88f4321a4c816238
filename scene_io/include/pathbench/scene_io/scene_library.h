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

// How scene files are read. strict: what a file holds that pathbench does not model (a
// texture, another BSDF or light) is an InputError instead of a warning.
struct SceneLoadOptions {
  bool strict = false;
};

// "paper-cornell", "furnace:0.5", or a scene file: .json, .obj, .ply, .off, .gltf, .glb or
// Mitsuba 3 .xml. The result is finalized. Throws InputError naming the scene or file
// (and, for a file, its format) and what is wrong.
Scene load_scene(const std::string& name_or_path, const SceneLoadOptions& options = {});

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

// A scene file (scene_io/src/readers/, one reader per format), by the file's extension (any
// case), finalized; InputError for one pathbench does not read.
Scene load_scene_file(const std::string& path, bool strict = false);
// True when `name` ends in an extension of a scene file pathbench reads.
bool is_scene_file_name(const std::string& name);

}  // namespace pb
