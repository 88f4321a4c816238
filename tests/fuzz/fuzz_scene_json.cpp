// The JSON scene reader on arbitrary bytes, through Scene::finalize. Mesh files named
// by the scene resolve to a small OBJ held in memory (so the fuzzer explores the JSON,
// the transforms and the range checks, not the file system).
#include "fuzz_util.h"
#include "pathbench/common/limits.h"
#include "readers/readers.h"

namespace {

const char* const kCube =
    "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // A mesh named "missing..." does not exist; every other name is the cube.
  static const pb::scene_io::FileReader reader = pb::fuzz::memory_reader([](const std::string&) { return kCube; });
  const std::string text = pb::fuzz::text_of(data, size);
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene("fuzz/scene.json", text, reader); });
  return 0;
}
