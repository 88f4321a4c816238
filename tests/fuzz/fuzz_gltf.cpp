// The glTF reader (tinygltf, then pathbench's accessor checks and node walk) on
// arbitrary bytes, through Scene::finalize. A first byte 'b' makes the rest a .glb,
// anything else a .gltf (the whole input); external buffer files resolve to the input
// itself (names containing "missing" do not exist).
#include "fuzz_util.h"
#include "scene_io/scene_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input = pb::fuzz::text_of(data, size);
  const bool binary = !input.empty() && input[0] == 'b';
  const std::string text = binary ? input.substr(1) : input;
  const pb::scene_io::FileReader reader = pb::fuzz::memory_reader([&](const std::string&) { return text; });
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene_gltf(binary ? "fuzz/s.glb" : "fuzz/s.gltf", text, binary, reader); });
  return 0;
}
