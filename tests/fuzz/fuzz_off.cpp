// The OFF reader on arbitrary bytes, through Scene::finalize.
#include "fuzz_util.h"
#include "scene_io/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = pb::fuzz::text_of(data, size);
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene_off("fuzz/mesh.off", text); });
  return 0;
}
