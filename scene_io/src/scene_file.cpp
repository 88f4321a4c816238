// Scene files by extension: the one entry point, which maps a file name to its reader (so that
// an error names the format ("tri.ply: malformed PLY: ...") and a format pathbench does
// not read is said to be one, not taken for an unknown built-in name) and finalizes the
// scene once.
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string_view>

#include "pathbench/common/errors.h"
#include "pathbench/output/image_io.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/limits.h"
#include "pathbench/scene_io/scene_library.h"
#include "readers/readers.h"

namespace pb {

namespace {

// The extension in lower case (image_io's, which means the same for any file).
std::string extension_of(const std::string& path) { return image_extension(path); }

constexpr std::string_view kReadable[] = {".json", ".obj", ".ply", ".off", ".gltf", ".glb", ".xml"};

// Scene and mesh formats users may try, with their names, that pathbench does not read.
constexpr std::pair<std::string_view, std::string_view> kOtherFormats[] = {
    {".stl", "STL"},  {".fbx", "FBX"},  {".dae", "COLLADA"}, {".3ds", "3DS"},   {".blend", "Blender"},
    {".usd", "USD"},  {".usda", "USD"}, {".usdc", "USD"},     {".usdz", "USD"}, {".pbrt", "pbrt"},
    {".abc", "Alembic"}, {".x3d", "X3D"}};

[[noreturn]] void throw_not_readable(const std::string& path, const std::string& ext) {
  for (const auto& [e, name] : kOtherFormats)
    if (ext == e)
      throw InputError(fmt::format("{}: {} files are not read by pathbench (scene files: .json, .obj, .ply, .off, "
                                   ".gltf, .glb, Mitsuba 3 .xml); convert it, e.g. to PLY or glTF", path, name));
  throw InputError(fmt::format("{}: unknown scene file type '{}' (expected .json, .obj, .ply, .off, .gltf, .glb or Mitsuba "
                               "3 .xml)", path, ext));
}

}  // namespace

bool is_scene_file_name(const std::string& name) {
  const std::string ext = extension_of(name);
  return std::find(std::begin(kReadable), std::end(kReadable), ext) != std::end(kReadable);
}

namespace scene_io {

Scene parse_scene(const std::string& path, const std::string& text, const FileReader& read, const Losses& losses) {
  const std::string ext = extension_of(path);
  Scene s;
  if (ext == ".json") s = parse_scene_json(path, text, read, losses);
  else if (ext == ".obj") s = parse_scene_obj(path, text, read, losses);
  else if (ext == ".ply") s = bare_mesh_scene(path, read_ply(path, text, losses), "a PLY mesh has no materials");
  else if (ext == ".off") s = bare_mesh_scene(path, read_off(path, text, losses), "an OFF mesh has no materials");
  else if (ext == ".gltf" || ext == ".glb") s = parse_scene_gltf(path, text, ext == ".glb", read, losses);
  else if (ext == ".xml") s = parse_scene_mitsuba(path, text, read, losses);
  else throw_not_readable(path, ext);
  s.finalize();
  return s;
}

}  // namespace scene_io

Scene load_scene_file(const std::string& path, bool strict) {
  const std::string ext = extension_of(path);
  if (!is_scene_file_name(path)) throw_not_readable(path, ext);
  // What the file is, for messages, and its size limit.
  const char* what = ext == ".json" ? "scene file (JSON)"
                     : ext == ".obj" ? "mesh file (OBJ)"
                     : ext == ".ply" ? "mesh file (PLY)"
                     : ext == ".off" ? "mesh file (OFF)"
                     : ext == ".gltf" ? "glTF file"
                     : ext == ".glb" ? "glTF file (GLB)"
                                     : "scene file (Mitsuba XML)";
  const uint64_t limit = ext == ".json" || ext == ".xml" ? limits::kMaxSceneJsonBytes : limits::kMaxMeshBytes;
  return scene_io::parse_scene(path, read_input_file(path, what, limit), scene_io::disk_reader(),
                               scene_io::Losses(strict));
}

}  // namespace pb
