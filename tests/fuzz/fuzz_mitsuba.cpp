// The Mitsuba 3 XML reader on arbitrary bytes, through Scene::finalize. Mesh files
// resolve to a small OBJ or PLY held in memory, by extension (so the fuzzer explores
// the XML, transforms, BSDFs and instancing, not the file system); names containing
// "missing" do not exist.
#include "fuzz_util.h"
#include "readers/readers.h"

namespace {

const char* const kObj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";
const char* const kPly =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const pb::scene_io::FileReader reader = pb::fuzz::memory_reader([](const std::string& path) {
    return path.size() > 4 && path.substr(path.size() - 4) == ".ply" ? kPly : kObj;
  });
  const std::string text = pb::fuzz::text_of(data, size);
  pb::fuzz::expect_clean([&] { pb::scene_io::parse_scene("fuzz/scene.xml", text, reader); });
  return 0;
}
