#pragma once
// The OBJ side of the scene readers, shared by the OBJ scene (obj_scene.cpp) and JSON
// scenes that place OBJ meshes (json_scene.cpp): a checked OBJ read, and the file
// reading and colour clamping both need. Private to common/src.
#include <tiny_obj_loader.h>

#include <string>
#include <vector>

#include "pathbench/common/scene.h"

namespace pb::scene_io {

// The whole file as text; InputError naming the file when it is missing, a directory or
// unreadable.
std::string read_text_file(const std::string& path);

struct ObjMesh {
  std::vector<Vec3f> positions;
  std::vector<Triangle> triangles;
  std::vector<int> material_ids;  // per triangle: index into `materials`, or -1 (none)
  std::vector<tinyobj::material_t> materials;
};

// tinyobjloader reads the file, but it skips what it cannot parse (a bad number becomes
// 0, an unknown line is ignored, an out-of-range index is kept), so a first pass checks
// every line and reports the first problem with its line number. `with_materials`: read
// the MTL files too.
ObjMesh read_obj(const std::string& path, bool with_materials);

// An MTL colour clamped to [0, 1].
Vec3f clamp01(const tinyobj::real_t* c);

}  // namespace pb::scene_io
