// The OBJ reader (and the MTL reader behind `mtllib`) on arbitrary bytes, through
// Scene::finalize. The input is an OBJ file; everything after a line "#mtl" is handed
// to it as the contents of whichever MTL library it names.
#include "fuzz_util.h"
#include "readers/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input = pb::fuzz::text_of(data, size);
  const size_t split = input.find("\n#mtl\n");
  const std::string obj = split == std::string::npos ? input : input.substr(0, split + 1);
  const std::string mtl = split == std::string::npos ? std::string() : input.substr(split + 6);
  // A library named "missing..." does not exist; every other name is the MTL part.
  const pb::scene_io::FileReader reader = pb::fuzz::memory_reader([&](const std::string&) { return mtl; });
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene("fuzz/mesh.obj", obj, reader); });
  return 0;
}
