#pragma once
// Private to pathbench_common (and the fuzz targets): the scene-file readers working
// on text already read, with every further file (an OBJ's MTL libraries, a JSON
// scene's meshes) read through a FileReader. Production reads files with
// read_input_file; the fuzzers hand in fixed or fuzzed text instead of files.
#include <cstdint>
#include <functional>
#include <string>

#include "pathbench/common/scene.h"

namespace pb::scene_io {

struct FileReader {
  // Returns the contents of `path`; throws InputError (missing, special, over max_bytes).
  std::function<std::string(const std::string& path, const char* what, uint64_t max_bytes)> read;
  // False only when `path` certainly does not exist (for "not found" messages with
  // the line or field that names it).
  std::function<bool(const std::string& path)> exists;
};
// read_input_file and std::filesystem::exists.
FileReader disk_reader();

// `text` is the file at `path` (for messages and to resolve relative names).
Scene parse_scene_json(const std::string& path, const std::string& text, const FileReader& read);
Scene parse_scene_obj(const std::string& path, const std::string& text, const FileReader& read);

// An OBJ mesh for a JSON scene (no materials, no camera).
struct ObjMesh;
void append_obj_mesh(Scene& s, const std::string& path, const std::string& text, Vec3f scale, Vec3f translate,
                     uint32_t material);

}  // namespace pb::scene_io
