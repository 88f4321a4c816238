// Scene files: JSON scene descriptions and bare OBJ meshes. (Being written.)
#include <fmt/core.h>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"

namespace pb {

Scene load_scene_json(const std::string& path) {
  throw InputError(fmt::format("{}: JSON scene files are not supported yet", path));
}
Scene load_scene_obj(const std::string& path) {
  throw InputError(fmt::format("{}: OBJ scene files are not supported yet", path));
}

}  // namespace pb
