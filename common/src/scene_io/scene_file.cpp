// Scene files by extension: the one place that maps a file name to its reader, so that
// an error names the format ("tri.ply: malformed PLY: ...") and a format pathbench does
// not read is said to be one, not taken for an unknown built-in name.
#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string_view>

#include "pathbench/common/errors.h"
#include "pathbench/common/image_io.h"
#include "pathbench/common/input_file.h"
#include "pathbench/common/limits.h"
#include "pathbench/common/scene_library.h"
#include "scene_io/scene_io.h"

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

}  // namespace

bool is_scene_file_name(const std::string& name) {
  const std::string ext = extension_of(name);
  return std::find(std::begin(kReadable), std::end(kReadable), ext) != std::end(kReadable);
}

Scene load_scene_file(const std::string& path, bool strict) {
  const std::string ext = extension_of(path);
  const scene_io::Losses losses(strict);
  if (ext == ".json") return load_scene_json(path, strict);
  if (ext == ".obj") return load_scene_obj(path, strict);
  if (ext == ".ply")
    return scene_io::parse_scene_ply(path, read_input_file(path, "mesh file (PLY)", limits::kMaxMeshBytes), losses);
  if (ext == ".off")
    return scene_io::parse_scene_off(path, read_input_file(path, "mesh file (OFF)", limits::kMaxMeshBytes), losses);
  if (ext == ".gltf" || ext == ".glb")
    return scene_io::parse_scene_gltf(path,
                                      read_input_file(path, ext == ".glb" ? "glTF file (GLB)" : "glTF file",
                                                      limits::kMaxMeshBytes),
                                      ext == ".glb", scene_io::disk_reader(), losses);
  if (ext == ".xml")
    return scene_io::parse_scene_mitsuba(path, read_input_file(path, "scene file (Mitsuba XML)", limits::kMaxSceneJsonBytes),
                                         scene_io::disk_reader(), losses);
  for (const auto& [e, name] : kOtherFormats)
    if (ext == e)
      throw InputError(fmt::format("{}: {} files are not read by pathbench (scene files: .json, .obj, .ply, .off, "
                                   ".gltf, .glb, Mitsuba 3 .xml); convert it, e.g. to PLY or glTF", path, name));
  throw InputError(fmt::format("{}: unknown scene file type '{}' (expected .json, .obj, .ply, .off, .gltf, .glb or Mitsuba "
                               "3 .xml)", path, ext));
}

}  // namespace pb
