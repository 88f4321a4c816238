// Hostile scene files, second round (issue 34): the readers' size arithmetic, nesting
// depth and placement counts. Every case is one InputError naming the file and the
// limit, found before the work it would cost; loading stays linear in placements and
// list lengths. The readers are driven on text in memory (scene_io.h).
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "pathbench/common/errors.h"
#include "test_scene_helpers.h"
#include "pathbench/common/json_input.h"
#include "pathbench/common/limits.h"
#include "pathbench/common/scene_warnings.h"
#include "readers/mitsuba.h"
#include "readers/readers.h"
#include "scenes/builder.h"

namespace pb {
namespace {

using scene_io::FileReader;

using scene_test::error_of;

// Buffer files resolve to `bin`; nothing else exists.
FileReader memory_files(const std::string& bin = "") {
  return {[bin](const std::string&, const char*, uint64_t) { return bin; }, [](const std::string&) { return true; }};
}

double seconds_of(const std::function<void()>& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One triangle, (0,0,0) (1,0,0) (0,1,0), as 36 bytes of floats in a base64 data URI.
const char* const kTriangleUri = "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";

// A glTF of that triangle with the accessor's and bufferView's extra members, the
// node list and root list given as JSON text, and `extra` members at the top.
std::string gltf(const std::string& accessor = "", const std::string& view = "",
                 const std::string& nodes = R"([{"mesh": 0}])", const std::string& roots = "[0]",
                 const std::string& extra = "") {
  return std::string(R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36, "uri": ")") + kTriangleUri +
         R"("}], "bufferViews": [{"buffer": 0, "byteLength": 36)" + view +
         R"(}], "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3")" + accessor +
         R"(}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}], "nodes": )" + nodes +
         R"(, "scenes": [{"nodes": )" + roots + "}]" + extra + "}";
}

Scene load_gltf(const std::string& text) {
  return scene_io::parse_scene("t.gltf", text, memory_files());
}

TEST(GltfLimits, TheTriangleLoads) {
  const Scene s = load_gltf(gltf());
  EXPECT_EQ(s.instances.size(), 1u);
}

// byteOffset + stride * (count - 1) + element wrapped in 64 bits: an accessor
// byteOffset of 2^64 - 4 passed the check and read 4 bytes before the buffer (exit 0);
// 2^64 - 16 and a bufferView offset near 2^64 the same way.
TEST(GltfLimits, OffsetsNear2To64DoNotWrapTheBoundsCheck) {
  for (const char* accessor : {R"(, "byteOffset": 18446744073709551612)", R"(, "byteOffset": 18446744073709551600)",
                               R"(, "byteOffset": 9223372036854775808)", R"(, "byteOffset": 4)"}) {
    const std::string e = error_of([&] { load_gltf(gltf(accessor)); });
    EXPECT_NE(e.find("t.gltf: glTF: mesh '' primitive 0: accessor 0 (byteOffset"), std::string::npos) << accessor << ": " << e;
    EXPECT_NE(e.find("reaches outside its bufferView 0"), std::string::npos) << e;
  }
  EXPECT_NE(error_of([&] { load_gltf(gltf("", R"(, "byteOffset": 18446744073709551615)")); })
                .find("reaches outside its bufferView 0 (byteOffset 18446744073709551615"),
            std::string::npos);
  EXPECT_NE(error_of([&] { load_gltf(gltf(R"(, "count": 18446744073709551615)")); }).find("t.gltf: glTF:"),
            std::string::npos);
}

// tinygltf converts extras and extensions to its Value recursively: 20,000 levels
// overflowed the stack (SIGSEGV). Refused from a scan of the text, before it parses.
TEST(GltfLimits, DeepJsonIsRefusedBeforeTinygltf) {
  const std::string deep_array = std::string(20000, '[') + std::string(20000, ']');
  std::string deep_object;
  for (int i = 0; i < 20000; ++i) deep_object += R"({"a":)";
  deep_object += "0" + std::string(20000, '}');
  for (const std::string& extra : {R"(, "extras": )" + deep_array, R"(, "extensions": {"X": )" + deep_object + "}"}) {
    EXPECT_EQ(error_of([&] { load_gltf(gltf("", "", R"([{"mesh": 0}])", "[0]", extra)); }),
              "t.gltf: JSON nested deeper than 64 levels (the supported maximum)");
  }
  // 64 levels load; brackets inside strings (escaped quotes too) are not nesting.
  std::string ok = R"(, "extras": {"s": "[[[[\"[[[[", "d": )";
  ok += std::string(61, '[') + std::string(61, ']') + "}";
  EXPECT_NO_THROW(load_gltf(gltf("", "", R"([{"mesh": 0}])", "[0]", ok)));
}

// A GLB whose JSON chunk holds `json` (padded to 4 bytes), then `bin` as its BIN chunk
// with the chunk length `bin_length` (the true one unless given).
std::string glb(std::string json, const std::string& bin, int64_t bin_length = -1) {
  while (json.size() % 4) json += ' ';
  auto u32 = [](uint64_t v) {
    std::string b(4, '\0');
    for (int i = 0; i < 4; ++i) b[size_t(i)] = char((v >> (8 * i)) & 0xff);
    return b;
  };
  const uint64_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size());
  std::string out = "glTF" + u32(2) + u32(total) + u32(json.size()) + "JSON" + json;
  if (!bin.empty()) out += u32(bin_length < 0 ? bin.size() : uint64_t(bin_length)) + std::string("BIN\0", 4) + bin;
  return out;
}

std::string glb_json(uint64_t byte_length) {
  return R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": )" + std::to_string(byte_length) +
         R"(}], "bufferViews": [{"buffer": 0, "byteLength": 36}], "accessors": [{"bufferView": 0, "componentType": 5126,
         "count": 3, "type": "VEC3"}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
         "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";
}

TEST(GltfLimits, GlbChunksMustLieInsideTheFile) {
  std::string bin(36, '\0');
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(bin.data(), xyz, sizeof xyz);
  const FileReader none = memory_files();
  EXPECT_NO_THROW(scene_io::parse_scene("t.glb", glb(glb_json(36), bin), none));
  // tinygltf 2.7 takes a BIN chunk length up to the file's end as its data, 8 bytes
  // (the chunk header) too far: a buffer of that length was copied from past the end.
  EXPECT_NE(error_of([&] { scene_io::parse_scene("t.glb", glb(glb_json(44), bin, 44), none); })
                .find("t.glb: malformed GLB: the BIN chunk (44 bytes from byte"),
            std::string::npos);
  // A buffer of byteLength 0 from the BIN chunk: tinygltf's data.at(0) threw
  // std::out_of_range (exit 3).
  EXPECT_NE(error_of([&] { scene_io::parse_scene("t.glb", glb(glb_json(0), bin), none); })
                .find("t.glb: malformed glTF:"),
            std::string::npos);
  // Deep JSON inside a GLB is scanned too.
  EXPECT_NE(error_of([&] {
              scene_io::parse_scene("t.glb", glb(std::string(100, '[') + std::string(100, ']'), bin), none);
            }).find("t.glb: JSON nested deeper than 64 levels"),
            std::string::npos);
  EXPECT_NE(error_of([&] { scene_io::parse_scene("t.glb", "glTF", none); }).find("t.glb: malformed GLB: 4 bytes"),
            std::string::npos);
}

// 2^20 values of JSON cost tinygltf ~1 GB and ~20 s (5 M values: 1.1 GB, 19 s here).
TEST(GltfLimits, JsonValuesAreBounded) {
  std::string many = R"(, "extras": [0)";
  many.reserve(2 * limits::kMaxGltfJsonValues + 32);
  for (uint64_t i = 0; i < limits::kMaxGltfJsonValues; ++i) many += ",0";
  many += "]";
  EXPECT_EQ(error_of([&] { load_gltf(gltf("", "", R"([{"mesh": 0}])", "[0]", many)); }),
            "t.gltf: more than 1048576 JSON values (the supported maximum)");
}

// 31 nodes, each naming the next twice as a child: 2^31 - 1 placements from 1.3 KB.
// Each placement copied the scene, so this did not load in 30 s; the paths are now
// counted before anything is placed.
TEST(GltfLimits, SharedNodesAreCountedBeforeTheyArePlaced) {
  std::string nodes = "[";
  for (int i = 0; i < 30; ++i) nodes += "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}, ";
  nodes += R"({"mesh": 0}])";
  std::string e;
  const double t = seconds_of([&] { e = error_of([&] { load_gltf(gltf("", "", nodes)); }); });
  EXPECT_EQ(e, "t.gltf: glTF: the node hierarchy places nodes more than 1048576 times (the supported maximum; a node "
               "that is the child of several nodes is placed once per path to it)");
  EXPECT_LT(t, 2.0);
  // A node shared by two parents is placed twice, as before.
  const Scene two = load_gltf(gltf("", "", R"([{"children": [2]}, {"children": [2], "translation": [5, 0, 0]}, {"mesh": 0}])",
                                   "[0, 1]"));
  EXPECT_EQ(two.instances.size(), 2u);
  EXPECT_EQ(two.triangles.size(), 2u + 2u);  // and the default light's quad
  // Triangles are counted the same way: 2^12 placements of 2^13 triangles.
  std::string wide = "[";
  for (int i = 0; i < 12; ++i) wide += "{\"children\": [" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]}, ";
  wide += R"({"mesh": 0}])";
  EXPECT_NE(error_of([&] { load_gltf(gltf(R"(, "count": 24576)", "", wide)); })
                .find("the placed meshes have more than 16777216 triangles in all (the supported maximum; mesh 0 is "
                      "placed 4096 times)"),
            std::string::npos);
  // A cycle, and a chain deeper than the limit.
  EXPECT_EQ(error_of([&] { load_gltf(gltf("", "", R"([{"children": [1]}, {"children": [0], "mesh": 0}])")); }),
            "t.gltf: glTF: the node hierarchy has a cycle (node 0 is on it or below it)");
  std::string chain = "[";
  for (int i = 0; i < 70; ++i) chain += "{\"children\": [" + std::to_string(i + 1) + "]}, ";
  chain += R"({"mesh": 0}])";
  EXPECT_EQ(error_of([&] { load_gltf(gltf("", "", chain)); }),
            "t.gltf: glTF: the node hierarchy is more than 64 levels deep (the supported maximum)");
}

// Placing a mesh reserved exactly its own size, so every placement reallocated (and
// copied) the scene's arrays: quadratic in the placements. Growth is geometric now.
TEST(PlacementLimits, AppendingMeshesReallocatesLogarithmically) {
  Scene s;
  s.name = "t";
  scene_io::MeshData quad = scene_io::mitsuba::rectangle_mesh();
  int reallocations = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const Vec3f* before = s.positions.data();
    scene_io::append_mesh(s, quad, Affine::translate(i, 0, 0), {0});
    reallocations += s.positions.data() != before;
  }
  EXPECT_EQ(s.positions.size(), 4u * n);
  EXPECT_LT(reallocations, 40);
  // Instances copy the prototype's arrays without a copy of the mesh per placement.
  const uint32_t proto = scene_io::add_prototype(s, "quad", quad, {0});
  for (int i = 0; i < 1000; ++i) scene_io::add_instance(s, proto, Affine::translate(0, i, 0));
  EXPECT_EQ(s.instances.size(), 1000u);
  const Vec3f corner = s.positions[s.positions.size() - 4];  // the last instance's first vertex
  EXPECT_EQ(corner.x, -1.0f);
  EXPECT_EQ(corner.y, 998.0f);
}

TEST(PlacementLimits, InstancesAreBounded) {
  Scene s;
  s.name = "t.json";
  const uint32_t proto = scene_io::add_prototype(s, "quad", scene_io::mitsuba::rectangle_mesh(), {0});
  s.instances.resize(limits::kMaxPlacements);
  EXPECT_EQ(error_of([&] { scene_io::add_instance(s, proto, Affine()); }),
            "t.json: more than 1048576 placed instances (the supported maximum)");
}

// nlohmann 3.11's callback parser (which bounded depth and keys) searched the enclosing
// array at the end of every object: 10^6 JSON instances took 133 s, 2x the list 4x
// the time. The bounds are a scan of the text now, and the parse has no callback.
TEST(JsonLimits, ArraysOfObjectsParseLinearly) {
  std::string list = "[";
  for (int i = 0; i < 300000; ++i) list += i ? ", {\"translate\": [1, 2, 3]}" : "{\"translate\": [1, 2, 3]}";
  list += "]";
  nlohmann::ordered_json j;
  const double t = seconds_of([&] { j = parse_json_bounded<nlohmann::ordered_json>(list, "t.json"); });
  EXPECT_EQ(j.size(), 300000u);
  EXPECT_LT(t, 5.0);
  // The bounds still hold: depth, keys per object (a colon inside a string is no key).
  EXPECT_EQ(error_of([] { parse_json_bounded<nlohmann::ordered_json>(std::string(65, '['), "d.json"); }),
            "d.json: JSON nested deeper than 64 levels (the supported maximum)");
  EXPECT_NO_THROW(parse_json_bounded<nlohmann::ordered_json>(std::string(64, '[') + std::string(64, ']'), "d.json"));
  std::string keys = "{\"a:b\": \"c:d\"";
  for (int i = 0; i < 9999; ++i) keys += ", \"k" + std::to_string(i) + "\": [{\"x\": 0}]";
  EXPECT_NO_THROW(parse_json_bounded<nlohmann::ordered_json>(keys + "}", "k.json"));
  EXPECT_EQ(error_of([&] { parse_json_bounded<nlohmann::ordered_json>(keys + ", \"one more\": 0}", "k.json"); }),
            "k.json: a JSON object with more than 10000 keys");
}

const char* const kSensor =
    R"(<sensor type="perspective"><transform name="to_world"><lookat origin="0,0,100" target="0,0,0"/></transform></sensor>)";

Scene load_mitsuba(const std::string& body) {
  return scene_io::parse_scene("t.xml", std::string("<scene version=\"3.0.0\">") + kSensor + body + "</scene>",
                                       memory_files());
}

// A sphere is the unit sphere moved: the same floats as tessellating it in place.
TEST(MitsubaLimits, SpheresAreTheUnitSphereMoved) {
  const Vec3f centre{3.25f, -1.5f, 7};
  const float radius = 0.37f;
  const scene_io::MeshData m = scene_io::mitsuba::sphere_mesh(centre, radius);
  Scene s;
  scenes::append_uv_sphere(s, centre, radius, 64, 32, 0);
  ASSERT_EQ(m.positions.size(), s.positions.size());
  EXPECT_EQ(m.triangles.size(), scene_io::mitsuba::kSphereTriangles);
  for (size_t i = 0; i < m.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.positions[i][k], s.positions[i][k]) << i;
}

// 4,096 spheres (300 KB) did not load in 30 s (each copied the scene), and each said
// "tessellated into 4096 triangles" on its own line.
TEST(MitsubaLimits, ManySpheresLoadLinearlyWithOneWarning) {
  std::string body;
  for (int i = 0; i < 1024; ++i)
    body += "<shape type=\"sphere\"><point name=\"center\" x=\"" + std::to_string(i % 32) + "\" y=\"" +
            std::to_string(i / 32) + "\" z=\"0\"/><float name=\"radius\" value=\"0.4\"/></shape>\n";
  SceneWarningCollector collect;
  Scene s;
  const double t = seconds_of([&] { s = load_mitsuba(body); });
  EXPECT_EQ(s.triangles.size(), 1024u * scene_io::mitsuba::kSphereTriangles);
  ASSERT_EQ(collect.messages().size(), 1u);
  EXPECT_EQ(collect.messages()[0].text,
            "t.xml: 1024 <shape type=\"sphere\">s tessellated into 4096 triangles each (pathbench traces triangles only)");
  EXPECT_LT(t, 20.0);
}

// "400:0.5, 401:0.5, ..." was parsed by copying the rest of the list after each entry:
// 4.7 MB took 30 s. A view moves along it now.
TEST(MitsubaLimits, LongSpectrumListsParseLinearly) {
  std::string list;
  for (int i = 0; i < 400000; ++i) list += std::to_string(400 + i % 400) + ":0.5, ";
  list += "700:0.5";
  Scene s;
  const double t = seconds_of([&] {
    s = load_mitsuba(R"(<shape type="rectangle"><bsdf type="diffuse"><spectrum name="reflectance" value=")" + list +
                     R"("/></bsdf></shape>)");
  });
  EXPECT_FLOAT_EQ(s.materials[s.material_ids[0]].albedo.x, 0.5f);
  EXPECT_LT(t, 5.0);
}

// "$a$a$a..." of a 1 MB <default>: a 300 KB file asked for 150 GB of attribute text.
TEST(MitsubaLimits, DefaultSubstitutionIsBounded) {
  std::string refs;
  for (int i = 0; i < 100; ++i) refs += "$a";
  const std::string e = error_of([&] {
    load_mitsuba("<default name=\"a\" value=\"" + std::string(1 << 20, 'x') + "\"/><shape type=\"" + refs + "\"/>");
  });
  EXPECT_NE(e.find("t.xml: Mitsuba XML: <shape type="), std::string::npos) << e;
  EXPECT_NE(e.find("the <default> values substituted for '$name's add up to more than 67108864 bytes"), std::string::npos)
      << e;
}


// The triangles instances expanded into are counted as they are placed (Scene's
// running count): appending a flat mesh summed every instance before, quadratic when
// flat meshes and placements alternate (Mitsuba shapes beside instances, glTF nodes).
// The count follows finalize() dropping zero-area triangles of an instance.
TEST(PlacementLimits, InstancedTriangleCountIsKeptWhilePlacing) {
  Scene s;
  s.name = "t.json";
  const scene_io::MeshData quad = scene_io::mitsuba::rectangle_mesh();
  const uint32_t proto = scene_io::add_prototype(s, "quad", quad, {0});
  constexpr int kPlacements = 60000;
  const double t = seconds_of([&] {
    for (int i = 0; i < kPlacements; ++i) {
      scene_io::add_instance(s, proto, Affine::translate(0, i, 0));
      scene_io::append_mesh(s, quad, Affine::translate(3, i, 0), {0});
    }
  });
  uint64_t sum = 0;
  for (const SceneInstance& in : s.instances) sum += in.triangle_count;
  EXPECT_EQ(sum, 2u * kPlacements);
  EXPECT_EQ(scene_io::instanced_triangles(s), sum);
  EXPECT_EQ(s.triangles.size(), 4u * kPlacements);
  EXPECT_LT(t, 3.0);  // ~0.05 s; summing every instance per flat mesh: ~20 s here

  Scene d;  // a prototype with a zero-area triangle, placed twice, beside a flat light
  d.name = "d.json";
  d.materials = {Material{{0.5f, 0.5f, 0.5f}, {0, 0, 0}}, Material{{0, 0, 0}, {1, 1, 1}}};
  scene_io::MeshData half = quad;
  half.triangles.push_back({{0, 0, 1}});
  const uint32_t p = scene_io::add_prototype(d, "half", half, {0});
  scene_io::add_instance(d, p, Affine());
  scene_io::add_instance(d, p, Affine::translate(0, 0, -1));
  scene_io::append_mesh(d, quad, Affine::translate(0, 0, 2), {1});
  EXPECT_EQ(scene_io::instanced_triangles(d), 6u);
  d.camera = Camera::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 50);
  SceneWarningCollector quiet;
  d.finalize();
  EXPECT_EQ(d.dropped_triangles, 2u);
  EXPECT_EQ(scene_io::instanced_triangles(d), 4u);
}

}  // namespace
}  // namespace pb
