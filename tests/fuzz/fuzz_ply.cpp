// The PLY reader on arbitrary bytes (ASCII and binary headers alike), through
// Scene::finalize.
#include "fuzz_util.h"
#include "readers/readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = pb::fuzz::text_of(data, size);
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene("fuzz/mesh.ply", text, pb::scene_io::FileReader{}); });
  return 0;
}
