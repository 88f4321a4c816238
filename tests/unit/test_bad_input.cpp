// Bad input: every case is one InputError whose message names the file (or option)
// and what is wrong. Fixtures: tests/data/scenes/ (one problem per file).
// tests/cli runs the same cases through the `pathbench` binary (exit status 2).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/common/settings.h"

namespace pb {
namespace {

const std::string kData = std::string(PATHBENCH_SOURCE_DIR) + "/tests/data/scenes/";

// Runs `f`, expects an InputError whose message contains every one of `parts`.
void expect_input_error(const std::function<void()>& f, std::initializer_list<std::string> parts) {
  try {
    f();
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const std::string& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
    return;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return;
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
}
void expect_scene_error(const std::string& spec, std::initializer_list<std::string> parts) {
  expect_input_error([&] { load_scene(spec); }, parts);
}

// Scene files.
TEST(BadSceneFile, MissingFile) { expect_scene_error(kData + "no-such-scene.json", {"no-such-scene.json", "no such file"}); }
TEST(BadSceneFile, MissingObjFile) { expect_scene_error(kData + "no-such-mesh.obj", {"no-such-mesh.obj", "no such file"}); }
TEST(BadSceneFile, TruncatedJson) {
  expect_scene_error(kData + "truncated.json", {"truncated.json", "malformed JSON", "unexpected end of input"});
}
TEST(BadSceneFile, MalformedJson) { expect_scene_error(kData + "malformed.json", {"malformed.json", "malformed JSON", "line 1"}); }
TEST(BadSceneFile, MalformedObj) { expect_scene_error(kData + "malformed.obj", {"malformed.obj:3:", "'one' is not a number"}); }
TEST(BadSceneFile, JsonWrongType) {
  expect_scene_error(kData + "wrong-type.json", {"wrong-type.json", "camera.position", "expected an array of 3 numbers"});
}
TEST(BadSceneFile, JsonMissingField) {
  expect_scene_error(kData + "missing-field.json", {"missing-field.json", "camera.look_at", "missing"});
}
TEST(BadSceneFile, JsonInfiniteCoordinate) {
  expect_scene_error(kData + "nan.json", {"nan.json", "triangles[0].vertices[1][0]", "not a finite number"});
}
TEST(BadSceneFile, JsonNumberOverflow) {
  expect_scene_error(kData + "overflow.json", {"overflow.json", "malformed JSON", "number overflow parsing '1e999'"});
}
TEST(BadSceneFile, ObjNanCoordinate) { expect_scene_error(kData + "nan.obj", {"nan.obj:2:", "NaN or infinite"}); }
TEST(BadSceneFile, JsonVertexIndexOutOfRange) {
  expect_scene_error(kData + "bad-index.json", {"bad-index.json", "triangles[0].indices[1][2]", "vertex index 5 is out of range"});
}
TEST(BadSceneFile, ObjVertexIndexOutOfRange) {
  expect_scene_error(kData + "bad-index.obj", {"bad-index.obj:4:", "vertex 7", "only 3 vertices"});
}
TEST(BadSceneFile, JsonUnknownMaterial) {
  expect_scene_error(kData + "unknown-material.json", {"unknown-material.json", "triangles[0].material", "unknown material 'blue'"});
}
TEST(BadSceneFile, ObjUnknownMaterial) {
  expect_scene_error(kData + "unknown-material.obj", {"unknown-material.obj:5:", "usemtl 'nosuch'"});
}
TEST(BadSceneFile, ObjMissingMaterialLibrary) {
  expect_scene_error(kData + "missing-mtl.obj", {"missing-mtl.obj:1:", "no-such.mtl", "not found"});
}
TEST(BadSceneFile, JsonMissingMeshFile) {
  expect_scene_error(kData + "missing-mesh.json", {"missing-mesh.json", "meshes[0].file", "no-such-mesh.obj", "no such file"});
}
TEST(BadSceneFile, OnlyZeroAreaTriangles) {
  testing::internal::CaptureStderr();
  expect_scene_error(kData + "all-zero-area.json", {"all-zero-area.json", "every triangle has zero area"});
  testing::internal::GetCapturedStderr();
}
TEST(BadSceneFile, UnknownFileType) { expect_scene_error(kData + "README.md", {"README.md", "unknown scene file type"}); }

// Built-in scene names and parameters.
TEST(BadSceneName, UnknownName) { expect_scene_error("cornell-bx", {"unknown scene 'cornell-bx'", "cornell-box"}); }
TEST(BadSceneName, IcoLevelNotANumber) { expect_scene_error("paper-cornell-ico:x", {"paper-cornell-ico:x", "'x' is not a number"}); }
TEST(BadSceneName, IcoLevelOutOfRange) { expect_scene_error("paper-cornell-ico:99", {"paper-cornell-ico:99", "out of range", "0 to 10"}); }
TEST(BadSceneName, IcoLevelNegative) { expect_scene_error("paper-cornell-ico:-1", {"out of range"}); }
TEST(BadSceneName, IcoLevelNotWhole) { expect_scene_error("paper-cornell-ico:1.5", {"whole number"}); }
TEST(BadSceneName, IcoLevelMissing) { expect_scene_error("paper-cornell-ico", {"needs a parameter", "level"}); }
TEST(BadSceneName, IcoTooManyParameters) { expect_scene_error("paper-cornell-ico:1,2", {"at most 1 parameter"}); }
TEST(BadSceneName, ScalingTooFew) { expect_scene_error("scaling:5", {"scaling:5", "out of range", "10 to 10000000"}); }
TEST(BadSceneName, ScalingTooMany) { expect_scene_error("scaling:2e7", {"out of range"}); }
TEST(BadSceneName, ScalingNotANumber) { expect_scene_error("scaling:many", {"'many' is not a number"}); }
TEST(BadSceneName, ParameterToAFixedScene) { expect_scene_error("cornell-box:2", {"cornell-box", "takes no parameters"}); }

// Scenes built in code: finalize() checks what the loaders cannot express.
Scene one_triangle() {
  Scene s;
  s.name = "test-scene";
  s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  s.triangles = {{{0, 1, 2}}};
  s.material_ids = {0};
  s.materials = {{{0.5f, 0.5f, 0.5f}, {1, 1, 1}}};
  s.material_names = {"grey"};
  s.camera = Camera::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 40);
  return s;
}
TEST(BadScene, MaterialIndexOutOfRange) {
  Scene s = one_triangle();
  s.material_ids[0] = 3;
  expect_input_error([&] { s.finalize(); }, {"test-scene", "triangle 0 refers to material 3"});
}
TEST(BadScene, VertexIndexOutOfRange) {
  Scene s = one_triangle();
  s.triangles[0].v[2] = 9;
  expect_input_error([&] { s.finalize(); }, {"test-scene", "refers to vertex 9"});
}
TEST(BadScene, NanVertex) {
  Scene s = one_triangle();
  s.positions[1].y = std::numeric_limits<float>::quiet_NaN();
  expect_input_error([&] { s.finalize(); }, {"test-scene", "vertex 1", "NaN"});
}

// Impossible settings (the CLI turns these strings and numbers into RenderSettings).
TEST(BadSettings, ZeroSpp) {
  RenderSettings s;
  s.spp = 0;
  expect_input_error([&] { s.validate(); }, {"--spp"});
}
TEST(BadSettings, ZeroWidth) {
  RenderSettings s;
  s.width = 0;
  expect_input_error([&] { s.validate(); }, {"--width"});
}
TEST(BadSettings, UnknownStrategy) { expect_input_error([] { parse_strategy("fastest"); }, {"--strategy", "'fastest'"}); }
TEST(BadSettings, UnknownSampling) { expect_input_error([] { parse_sampling("importance"); }, {"--sampling", "'importance'"}); }
TEST(BadSettings, UnknownDevice) { expect_input_error([] { parse_device("tpu"); }, {"--device", "'tpu'"}); }

}  // namespace
}  // namespace pb
