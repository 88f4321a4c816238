// The glTF reader (the checks before tinygltf, tinygltf, then pathbench's accessor
// checks and node walk) on arbitrary bytes, through Scene::finalize. The first byte
// picks the form:
//   'b' + bytes                   the rest is a .glb
//   'd' + 2 bytes (n) + text      a .gltf: the first '@' in the text becomes n levels of
//                                 '[' ... ']' (deep JSON beyond -max_len)
//   'r' + 2 bytes (n) + text      a .gltf: the text between the first two '@'s is
//                                 repeated 16 n times, to 8 MiB (long lists, many nodes)
//   anything else                 the whole input is a .gltf
// External buffer files resolve to the input itself (names containing "missing" do
// not exist).
#include <cstddef>

#include "fuzz_util.h"
#include "readers/readers.h"

namespace {

// The text of a 'd' or 'r' input, expanded.
std::string expanded(const std::string& input) {
  if (input.size() < 3) return input;
  const size_t n = static_cast<unsigned char>(input[1]) | size_t(static_cast<unsigned char>(input[2])) << 8;
  std::string text = input.substr(3);
  const size_t at = text.find('@');
  if (at == std::string::npos) return text;
  if (input[0] == 'd') return text.substr(0, at) + std::string(n, '[') + std::string(n, ']') + text.substr(at + 1);
  const size_t end = text.find('@', at + 1);
  if (end == std::string::npos) return text;
  const std::string item = text.substr(at + 1, end - at - 1);
  std::string out = text.substr(0, at);
  for (size_t i = 0; i < 16 * n && out.size() < (size_t(8) << 20); ++i) out += item;
  return out + text.substr(end + 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input = pb::fuzz::text_of(data, size);
  const char form = input.empty() ? 0 : input[0];
  const bool binary = form == 'b';
  const std::string text = binary ? input.substr(1) : form == 'd' || form == 'r' ? expanded(input) : input;
  const pb::scene_io::FileReader reader = pb::fuzz::memory_reader([&](const std::string&) { return text; });
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene(binary ? "fuzz/s.glb" : "fuzz/s.gltf", text, reader); });
  return 0;
}
